// A thin RAII layer over the SQLite C API for the job store: one connection, statements
// prepared from constant SQL with values bound as parameters (never spliced into the SQL), and
// every return code checked. A failure throws parapm::Error naming the operation, SQLite's
// message and the database file.
//
// Not thread-safe: JobStore serialises all use of one Database behind its mutex.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

struct sqlite3;
struct sqlite3_stmt;

namespace parapm::service::sqlite {

class Database {
 public:
  // Opens or creates the file. Throws kIo when it cannot be opened.
  explicit Database(const std::filesystem::path& file);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  // Runs SQL that binds nothing (schema, pragmas, BEGIN/COMMIT). `what` names the operation
  // for the error message.
  void exec(const char* sql, const std::string& what);

  // Throws the Error for return code `rc` of operation `what`: a foreign-key violation is
  // kNotFound (a row named a parent that does not exist), any other constraint kInvalidInput
  // (e.g. a duplicate id), everything else kIo.
  [[noreturn]] void fail(int rc, const std::string& what) const;

  sqlite3* handle() const { return db_; }
  const std::filesystem::path& file() const { return file_; }
  int changes() const;  // rows changed by the last INSERT/UPDATE/DELETE

 private:
  sqlite3* db_ = nullptr;
  std::filesystem::path file_;
};

// One prepared statement. Bind indices are 1-based, column indices 0-based (SQLite's own
// convention).
class Statement {
 public:
  Statement(Database& db, std::string_view sql, std::string what);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind_text(int index, std::string_view text);
  Statement& bind_blob(int index, std::string_view bytes);
  Statement& bind_int64(int index, int64_t value);
  // SQLite integers are signed 64-bit: a larger value throws kInvalidInput instead of wrapping.
  Statement& bind_uint64(int index, uint64_t value);
  Statement& bind_double(int index, double value);

  bool step();  // true when a row is ready, false when done
  void run();   // steps a statement that returns no rows

  std::string column_text(int column) const;  // NULL reads as ""
  std::string column_blob(int column) const;  // NULL reads as ""
  int64_t column_int64(int column) const;
  uint64_t column_uint64(int column) const;  // a negative value throws kIo (a corrupt row)
  double column_double(int column) const;

 private:
  void check_bind(int rc);

  Database& db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string what_;
};

// BEGIN IMMEDIATE ... COMMIT; rolls back when destroyed without commit(), e.g. by an exception.
class Transaction {
 public:
  Transaction(Database& db, const std::string& what);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Database& db_;
  std::string what_;
  bool open_ = true;
};

}  // namespace parapm::service::sqlite
