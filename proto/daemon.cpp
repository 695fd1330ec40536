#include "daemon.h"

#include <pthread.h>
#include <csignal>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "rpc_security.h"
#include "util/error.h"

namespace parapm::rpc {
namespace {
sigset_t shutdown_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

void set_up_logging(const std::string& program, const std::string& level) {
  const spdlog::level::level_enum parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off")
    throw_invalid("unknown log level '" + level + "' (trace, debug, info, warn, error, off)");
  auto logger = spdlog::stderr_color_mt(program);
  logger->set_level(parsed);
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
