#include "daemon.h"

#include <pthread.h>
#include <csignal>
#include <ctime>

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "rpc_security.h"
#include "util/error.h"

namespace parapm::rpc {
namespace {
// One JSON object per line: {"time": "2026-11-27T08:15:02.123Z" (UTC), "level", "logger",
// "message"}; bytes of a message that are not UTF-8 are replaced.
class JsonLineFormatter final : public spdlog::formatter {
 public:
  void format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) override {
    const auto since_epoch = msg.time.time_since_epoch();
    const std::time_t seconds =
        std::chrono::duration_cast<std::chrono::seconds>(since_epoch).count();
    const auto millis =
        std::chrono::duration_cast<std::chrono::milliseconds>(since_epoch).count() % 1000;
    std::tm utc{};
    gmtime_r(&seconds, &utc);
    char time[40];
    const size_t n = std::strftime(time, sizeof time, "%Y-%m-%dT%H:%M:%S", &utc);
    std::snprintf(time + n, sizeof time - n, ".%03dZ", int(millis));
    const spdlog::string_view_t level = spdlog::level::to_string_view(msg.level);
    const nlohmann::ordered_json line = {
        {"time", time},
        {"level", std::string(level.data(), level.size())},
        {"logger", std::string(msg.logger_name.data(), msg.logger_name.size())},
        {"message", std::string(msg.payload.data(), msg.payload.size())}};
    const std::string text =
        line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
    dest.append(text.data(), text.data() + text.size());
  }
  std::unique_ptr<spdlog::formatter> clone() const override {
    return std::make_unique<JsonLineFormatter>();
  }
};

sigset_t shutdown_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

void set_up_logging(const std::string& program, const std::string& level,
                    const std::string& format) {
  const spdlog::level::level_enum parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off")
    throw_invalid("unknown log level '" + level + "' (trace, debug, info, warn, error, off)");
  if (format != "text" && format != "json")
    throw_invalid("unknown log format '" + format + "' (text, json)");
  auto logger =
      format == "json" ? spdlog::stderr_logger_mt(program) : spdlog::stderr_color_mt(program);
  logger->set_level(parsed);
  if (format == "json")
    logger->set_formatter(std::make_unique<JsonLineFormatter>());
  else
    logger->set_pattern("%Y-%m-%d %H:%M:%S.%e [%n] %^%l%$ %v");
  spdlog::set_default_logger(logger);
}

std::string token_for_listening(const std::string& token_file, const std::string& listen) {
  std::string token = load_token(token_file);
  if (token.empty() && !is_loopback_address(listen))
    throw_invalid("refusing to listen on " + listen +
                  " without a token: beyond loopback every call needs one (--token-file FILE "
                  "or PARAPM_TOKEN)");
  return token;
}

void block_shutdown_signals() {
  const sigset_t set = shutdown_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

std::string wait_for_shutdown_signal() {
  const sigset_t set = shutdown_signals();
  int signal = 0;
  sigwait(&set, &signal);
  return signal == SIGINT ? "SIGINT" : "SIGTERM";
}

}  // namespace parapm::rpc
