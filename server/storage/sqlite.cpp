#include "storage/sqlite.h"

#include <spdlog/spdlog.h>
#include <sqlite3.h>
#include <limits>

#include "util/error.h"

namespace parapm::service::sqlite {

// ---- Database

Database::Database(const std::filesystem::path& file) : file_(file) {
  const int rc =
      sqlite3_open_v2(file.c_str(), &db_,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    // Even a failed open returns a handle (unless out of memory) that holds the message.
    const std::string message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw Error(ErrorCode::kIo, "job store: opening " + file.string() + ": " + message);
  }
  // Extended codes tell a foreign-key violation from other constraint failures.
  sqlite3_extended_result_codes(db_, 1);
}

Database::~Database() {
  // Every Statement is finalised by its own destructor first, so close cannot be blocked.
  if (db_ && sqlite3_close_v2(db_) != SQLITE_OK)
    spdlog::warn("job store: closing {}: {}", file_.string(), sqlite3_errmsg(db_));
}

void Database::exec(const char* sql, const std::string& what) {
  const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, nullptr);
  if (rc != SQLITE_OK) fail(rc, what);
}

void Database::fail(int rc, const std::string& what) const {
  ErrorCode code = ErrorCode::kIo;
  if (rc == SQLITE_CONSTRAINT_FOREIGNKEY)
    code = ErrorCode::kNotFound;
  else if ((rc & 0xff) == SQLITE_CONSTRAINT)
    code = ErrorCode::kInvalidInput;
  throw Error(code,
              "job store: " + what + ": " + sqlite3_errmsg(db_) + " (" + file_.string() + ")");
}

int Database::changes() const { return sqlite3_changes(db_); }

// ---- Statement

Statement::Statement(Database& db, std::string_view sql, std::string what)
    : db_(db), what_(std::move(what)) {
  const int rc =
      sqlite3_prepare_v2(db_.handle(), sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr);
  if (rc != SQLITE_OK) db_.fail(rc, what_);
}

Statement::~Statement() { sqlite3_finalize(stmt_); }

void Statement::check_bind(int rc) {
  if (rc != SQLITE_OK) db_.fail(rc, what_);
}

Statement& Statement::bind_text(int index, std::string_view text) {
  // A null data pointer would bind SQL NULL, so an empty view binds "" instead.
  check_bind(sqlite3_bind_text64(stmt_, index, text.data() ? text.data() : "", text.size(),
                                 SQLITE_TRANSIENT, SQLITE_UTF8));
  return *this;
}

Statement& Statement::bind_blob(int index, std::string_view bytes) {
  check_bind(sqlite3_bind_blob64(stmt_, index, bytes.data() ? bytes.data() : "", bytes.size(),
                                 SQLITE_TRANSIENT));
  return *this;
}

Statement& Statement::bind_int64(int index, int64_t value) {
  check_bind(sqlite3_bind_int64(stmt_, index, value));
  return *this;
}

Statement& Statement::bind_uint64(int index, uint64_t value) {
  if (value > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()))
    throw_invalid("job store: " + what_ + ": value " + std::to_string(value) +
                  " does not fit a 64-bit signed integer");
  return bind_int64(index, static_cast<int64_t>(value));
}

Statement& Statement::bind_double(int index, double value) {
  check_bind(sqlite3_bind_double(stmt_, index, value));
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  db_.fail(rc, what_);
}

void Statement::run() {
  if (step()) throw_internal("job store: " + what_ + ": returned a row where none was expected");
}

std::string Statement::column_text(int column) const {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
  // column_bytes after column_text gives the length of the text, embedded NULs included.
  const int size = sqlite3_column_bytes(stmt_, column);
  return text ? std::string(text, static_cast<size_t>(size)) : std::string();
}

std::string Statement::column_blob(int column) const {
  const auto* bytes = static_cast<const char*>(sqlite3_column_blob(stmt_, column));
  const int size = sqlite3_column_bytes(stmt_, column);
  return bytes ? std::string(bytes, static_cast<size_t>(size)) : std::string();
}

int64_t Statement::column_int64(int column) const { return sqlite3_column_int64(stmt_, column); }

uint64_t Statement::column_uint64(int column) const {
  const int64_t value = sqlite3_column_int64(stmt_, column);
  if (value < 0)
    throw Error(ErrorCode::kIo, "job store: " + what_ + ": negative value " +
                                    std::to_string(value) + " in an unsigned column (" +
                                    db_.file().string() + ")");
  return static_cast<uint64_t>(value);
}

double Statement::column_double(int column) const { return sqlite3_column_double(stmt_, column); }

// ---- Transaction

Transaction::Transaction(Database& db, const std::string& what) : db_(db), what_(what) {
  // IMMEDIATE takes the write lock up front, so a read-then-write cannot be overtaken by
  // another process between the read and the write.
  db_.exec("BEGIN IMMEDIATE", what_ + " (begin)");
}

Transaction::~Transaction() {
  // An error may already have ended the transaction (SQLite rolls back on some failures).
  if (open_ && !sqlite3_get_autocommit(db_.handle()) &&
      sqlite3_exec(db_.handle(), "ROLLBACK", nullptr, nullptr, nullptr) != SQLITE_OK)
    spdlog::warn("job store: rolling back {}: {}", what_, sqlite3_errmsg(db_.handle()));
}

void Transaction::commit() {
  db_.exec("COMMIT", what_ + " (commit)");
  open_ = false;
}

}  // namespace parapm::service::sqlite
