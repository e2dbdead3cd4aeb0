#include "tessera/server/store.h"

#include <sqlite3.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace tessera::server {
namespace {

constexpr const char* kSchema = R"(
CREATE TABLE IF NOT EXISTS scenes(hash TEXT PRIMARY KEY, bytes INTEGER NOT NULL, created REAL NOT NULL);
CREATE TABLE IF NOT EXISTS jobs(id INTEGER PRIMARY KEY AUTOINCREMENT, name TEXT NOT NULL, plan TEXT NOT NULL,
  priority INTEGER NOT NULL, state TEXT NOT NULL, error TEXT NOT NULL DEFAULT '', created REAL NOT NULL,
  started REAL NOT NULL DEFAULT 0, finished REAL NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS results(job INTEGER NOT NULL, tile INTEGER NOT NULL, pass INTEGER NOT NULL,
  worker INTEGER NOT NULL, data BLOB NOT NULL, ack_seq INTEGER NOT NULL, acked REAL NOT NULL,
  PRIMARY KEY(job, pass, tile));
CREATE TABLE IF NOT EXISTS leases(seq INTEGER PRIMARY KEY AUTOINCREMENT, job INTEGER NOT NULL,
  tile INTEGER NOT NULL, pass INTEGER NOT NULL, worker INTEGER NOT NULL, issued REAL NOT NULL);
CREATE INDEX IF NOT EXISTS leases_by_unit ON leases(job, pass, tile);
CREATE TABLE IF NOT EXISTS workers(id INTEGER PRIMARY KEY AUTOINCREMENT, name TEXT NOT NULL, threads INTEGER NOT NULL,
  memory INTEGER NOT NULL, version TEXT NOT NULL, isa TEXT NOT NULL, registered REAL NOT NULL,
  last_seen REAL NOT NULL, state TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS checkpoints(job INTEGER NOT NULL, tile INTEGER NOT NULL, passes INTEGER NOT NULL,
  data BLOB NOT NULL, PRIMARY KEY(job, tile));
CREATE TABLE IF NOT EXISTS pass_plans(job INTEGER NOT NULL, pass INTEGER NOT NULL, data BLOB NOT NULL,
  PRIMARY KEY(job, pass));
CREATE TABLE IF NOT EXISTS guides(job INTEGER NOT NULL, iteration INTEGER NOT NULL, hash TEXT NOT NULL,
  PRIMARY KEY(job, iteration));
CREATE TABLE IF NOT EXISTS training(job INTEGER NOT NULL, pass INTEGER NOT NULL, tile INTEGER NOT NULL,
  data BLOB NOT NULL, PRIMARY KEY(job, pass, tile));
CREATE TABLE IF NOT EXISTS expired_jobs(id INTEGER PRIMARY KEY, name TEXT NOT NULL, expired REAL NOT NULL);
)";

// SQLite reports a full disk as SQLITE_FULL, or as an I/O error whose errno is ENOSPC/EDQUOT
// (a failed fsync or WAL write). Either way the statement's transaction was rolled back: the
// database is as it was before, and the caller answers 507.
bool disk_full(sqlite3* db) {
  if (!db) return false;
  const int code = sqlite3_errcode(db);
  if (code == SQLITE_FULL) return true;
  const int err = sqlite3_system_errno(db);
  return code == SQLITE_IOERR && (err == ENOSPC || err == EDQUOT);
}

[[noreturn]] void throw_error(sqlite3* db, const std::string& msg) {
  if (disk_full(db)) {
    const char* file = sqlite3_db_filename(db, "main");
    throw DiskFullError(msg, file ? std::filesystem::path(file).parent_path().string() : "");
  }
  throw StoreError(msg, false);
}

[[noreturn]] void fail(sqlite3* db, const std::string& what) {
  throw_error(db, "state database: " + what + ": " + (db ? sqlite3_errmsg(db) : "cannot open"));
}

// A prepared statement that binds left to right and finalises itself, or (borrowed from the
// store's cache) is reset for its next use.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) fail(db, "prepare");
  }
  Stmt(sqlite3* db, sqlite3_stmt* borrowed) : db_(db), stmt_(borrowed), owned_(false) {}
  ~Stmt() {
    if (owned_) {
      sqlite3_finalize(stmt_);
    } else {
      sqlite3_reset(stmt_);
      sqlite3_clear_bindings(stmt_);
    }
  }
  Stmt& bind(int64_t v) { return check(sqlite3_bind_int64(stmt_, ++n_, v)); }
  Stmt& bind(double v) { return check(sqlite3_bind_double(stmt_, ++n_, v)); }
  Stmt& bind(const std::string& v) {
    return check(sqlite3_bind_text(stmt_, ++n_, v.data(), int(v.size()), SQLITE_TRANSIENT));
  }
  Stmt& blob(std::string_view v) {
    // (An empty view may have no pointer, which SQLite would store as NULL, not as no bytes.)
    return check(sqlite3_bind_blob64(stmt_, ++n_, v.empty() ? "" : v.data(), v.size(), SQLITE_TRANSIENT));
  }
  /// True while there is a row; throws on errors (a constraint violation returns false with
  /// constraint() set).
  bool step() {
    int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    if (rc == SQLITE_CONSTRAINT) {
      constraint_ = true;
      return false;
    }
    fail(db_, "step");
  }
  bool constraint() const { return constraint_; }
  /// Ready to bind and step again.
  void reset() {
    sqlite3_reset(stmt_);
    n_ = 0;
  }
  int64_t i(int col) const { return sqlite3_column_int64(stmt_, col); }
  double d(int col) const { return sqlite3_column_double(stmt_, col); }
  std::string s(int col) const {
    const void* p = sqlite3_column_blob(stmt_, col);
    return p ? std::string(static_cast<const char*>(p), size_t(sqlite3_column_bytes(stmt_, col))) : std::string();
  }

 private:
  Stmt& check(int rc) {
    if (rc != SQLITE_OK) fail(db_, "bind");
    return *this;
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  bool owned_ = true;
  int n_ = 0;
  bool constraint_ = false;
};

}  // namespace

namespace {
sqlite3* open_connection(const std::string& path, int flags) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, flags | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw StoreError("cannot open the state database " + path, false);
  }
  sqlite3_busy_timeout(db, 5000);
  return db;
}
}  // namespace

Store::Store(const std::string& path) {
  db_ = open_connection(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  try {
    // These two only take effect in a new database (before its first table), and are set only then:
    // on an existing database the pragmas write, which fails on a full disk. 64 KiB pages: a tile's
    // checkpoint (56 bytes a pixel, 32x32 by default) is one page, written as one frame of the log,
    // not a chain of overflow pages. Pages freed by retention go back to the file system at
    // incremental_vacuum(); older databases reuse them instead.
    if (!Stmt(db_, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'jobs'").step()) {
      exec("PRAGMA page_size=65536");
      exec("PRAGMA auto_vacuum=INCREMENTAL");
    }
    // WAL keeps readers off the writer's back; FULL fsyncs the log at every commit, which is what
    // makes an acknowledged result survive a crash. The log is checkpointed into the database
    // every 4 MiB of it (SQLite's default in bytes: a larger log needs that much more free disk).
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=FULL");
    exec("PRAGMA cache_size=-32768");
    exec("PRAGMA wal_autocheckpoint=64");
    exec(kSchema);
    // Reads get a connection of their own: they see committed data only, never a batch that the
    // writer has open, and never wait for its fsync.
    rd_ = open_connection(path, SQLITE_OPEN_READONLY);
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

Store::~Store() {
  for (auto& [sql, stmt] : prepared_) sqlite3_finalize(stmt);
  sqlite3_close(rd_);
  sqlite3_close(db_);
}

void Store::transaction(const std::function<void()>& writes) {
  WriteLock lock(write_mu_);
  exec("BEGIN IMMEDIATE");
  try {
    writes();
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

sqlite3_stmt* Store::prepared(const char* sql) {
  sqlite3_stmt*& stmt = prepared_[sql];
  if (!stmt && sqlite3_prepare_v3(db_, sql, -1, SQLITE_PREPARE_PERSISTENT, &stmt, nullptr) != SQLITE_OK) {
    prepared_.erase(sql);
    fail(db_, "prepare");
  }
  return stmt;
}

void Store::exec(const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    std::string msg = err ? err : "error";
    sqlite3_free(err);
    const std::string statement(sql, std::min<size_t>(std::strlen(sql), 40));
    throw_error(db_, "state database: " + msg + " (at " + statement + (std::strlen(sql) > 40 ? "...)" : ")"));
  }
}

void Store::add_scene(const std::string& hash, uint64_t bytes, double now) {
  WriteLock lock(write_mu_);
  Stmt st(db_, "INSERT OR IGNORE INTO scenes(hash, bytes, created) VALUES(?, ?, ?)");
  st.bind(hash).bind(int64_t(bytes)).bind(now).step();
}

bool Store::has_scene(const std::string& hash) {
  Stmt st(rd_, "SELECT 1 FROM scenes WHERE hash = ?");
  return st.bind(hash).step();
}

uint64_t Store::add_job(const std::string& name, const std::string& plan_json, int priority, double now) {
  WriteLock lock(write_mu_);
  Stmt st(db_, "INSERT INTO jobs(name, plan, priority, state, created) VALUES(?, ?, ?, 'queued', ?)");
  st.bind(name).bind(plan_json).bind(int64_t(priority)).bind(now).step();
  return uint64_t(sqlite3_last_insert_rowid(db_));
}

void Store::set_job_state(uint64_t id, const std::string& state, const std::string& error, double started,
                          double finished) {
  WriteLock lock(write_mu_);
  Stmt st(db_, "UPDATE jobs SET state = ?, error = ?, started = ?, finished = ? WHERE id = ?");
  st.bind(state).bind(error).bind(started).bind(finished).bind(int64_t(id)).step();
}

void Store::set_job_priority(uint64_t id, int priority) {
  WriteLock lock(write_mu_);
  Stmt st(db_, "UPDATE jobs SET priority = ? WHERE id = ?");
  st.bind(int64_t(priority)).bind(int64_t(id)).step();
}

std::vector<JobRow> Store::jobs() {
  Stmt st(rd_, "SELECT id, name, plan, priority, state, error, created, started, finished FROM jobs ORDER BY id");
  std::vector<JobRow> rows;
  while (st.step())
    rows.push_back({uint64_t(st.i(0)), st.s(1), st.s(2), st.s(4), st.s(5), int(st.i(3)), st.d(6), st.d(7), st.d(8)});
  return rows;
}

void Store::log_lease(uint64_t seq, uint64_t job, uint32_t tile, uint32_t pass, uint64_t worker, double now) {
  WriteLock lock(write_mu_);
  Stmt st(db_, prepared("INSERT INTO leases(seq, job, tile, pass, worker, issued) VALUES(?, ?, ?, ?, ?, ?)"));
  st.bind(int64_t(seq)).bind(int64_t(job)).bind(int64_t(tile)).bind(int64_t(pass)).bind(int64_t(worker)).bind(now);
  if (!st.step() && st.constraint()) fail(db_, "lease " + std::to_string(seq) + " logged twice");
}

uint64_t Store::last_worker_id() {
  Stmt st(rd_, "SELECT COALESCE((SELECT seq FROM sqlite_sequence WHERE name = 'workers'), 0)");
  st.step();
  return uint64_t(st.i(0));
}

uint64_t Store::last_lease_seq() {
  // AUTOINCREMENT's counter: never lowered, also once retention has deleted the newest leases.
  Stmt st(rd_, "SELECT COALESCE((SELECT seq FROM sqlite_sequence WHERE name = 'leases'), 0)");
  st.step();
  return uint64_t(st.i(0));
}

bool Store::add_result(uint64_t job, uint32_t tile, uint32_t pass, uint64_t worker, std::string_view data,
                       double now) {
  WriteLock lock(write_mu_);
  // ack_seq: the newest lease at acknowledgement; any lease for this pass with a larger sequence
  // number was issued after the pass was safe (reissued_after_ack).
  Stmt st(db_, prepared("INSERT INTO results(job, tile, pass, worker, data, ack_seq, acked) "
                        "VALUES(?, ?, ?, ?, ?, (SELECT COALESCE(MAX(seq), 0) FROM leases), ?)"));
  st.bind(int64_t(job)).bind(int64_t(tile)).bind(int64_t(pass)).bind(int64_t(worker)).blob(data).bind(now);
  st.step();
  return !st.constraint();
}

void Store::save_checkpoint(uint64_t job, uint32_t tile, uint32_t passes, const std::string& data,
                            const std::vector<uint32_t>& held) {
  WriteLock lock(write_mu_);
  // Updated in place: a tile's checkpoints all have one size, so SQLite overwrites the row's pages
  // rather than freeing and allocating them (fewer pages written per commit).
  Stmt(db_, prepared("UPDATE checkpoints SET passes = ?, data = ? WHERE job = ? AND tile = ?"))
      .bind(int64_t(passes)).blob(data).bind(int64_t(job)).bind(int64_t(tile)).step();
  if (sqlite3_changes(db_) == 0)
    Stmt(db_, prepared("INSERT INTO checkpoints(job, tile, passes, data) VALUES(?, ?, ?, ?)"))
        .bind(int64_t(job)).bind(int64_t(tile)).bind(int64_t(passes)).blob(data).step();
  // The passes it holds keep their rows (for restart, retry and the lease log) without their bytes.
  Stmt drop(db_, prepared("UPDATE results SET data = x'' WHERE job = ? AND pass = ? AND tile = ?"));
  for (uint32_t pass : held) {
    drop.bind(int64_t(job)).bind(int64_t(pass)).bind(int64_t(tile)).step();
    drop.reset();
  }
}

void Store::for_each_checkpoint(uint64_t job, const std::function<void(CheckpointRow&&)>& fn) {
  Stmt st(rd_, "SELECT tile, passes, data FROM checkpoints WHERE job = ? ORDER BY tile");
  st.bind(int64_t(job));
  while (st.step()) fn(CheckpointRow{uint32_t(st.i(0)), uint32_t(st.i(1)), st.s(2)});
}

void Store::save_pass_plan(uint64_t job, uint32_t pass, const std::string& data) {
  WriteLock lock(write_mu_);
  Stmt(db_, prepared("INSERT OR REPLACE INTO pass_plans(job, pass, data) VALUES(?, ?, ?)"))
      .bind(int64_t(job)).bind(int64_t(pass)).blob(data).step();
}

void Store::for_each_pass_plan(uint64_t job, const std::function<void(uint32_t, std::string&&)>& fn) {
  Stmt st(rd_, "SELECT pass, data FROM pass_plans WHERE job = ? ORDER BY pass");
  st.bind(int64_t(job));
  while (st.step()) fn(uint32_t(st.i(0)), st.s(1));
}

void Store::save_guide(uint64_t job, uint32_t iteration, const std::string& hash, uint32_t fed_before) {
  WriteLock lock(write_mu_);
  Stmt(db_, prepared("INSERT OR REPLACE INTO guides(job, iteration, hash) VALUES(?, ?, ?)"))
      .bind(int64_t(job)).bind(int64_t(iteration)).bind(hash).step();
  Stmt(db_, prepared("DELETE FROM training WHERE job = ? AND pass < ?")).bind(int64_t(job)).bind(int64_t(fed_before)).step();
}

void Store::spend_guide(uint64_t job, uint32_t iteration) {
  WriteLock lock(write_mu_);
  Stmt(db_, prepared("UPDATE guides SET hash = '' WHERE job = ? AND iteration = ?")).bind(int64_t(job)).bind(int64_t(iteration)).step();
}

bool Store::guide_named(const std::string& hash) {
  Stmt st(rd_, "SELECT 1 FROM guides WHERE hash = ? LIMIT 1");
  st.bind(hash);
  return st.step();
}

std::vector<std::string> Store::guides(uint64_t job) {
  Stmt st(rd_, "SELECT iteration, hash FROM guides WHERE job = ? ORDER BY iteration");
  st.bind(int64_t(job));
  std::vector<std::string> out;
  while (st.step() && uint64_t(st.i(0)) == out.size()) out.push_back(st.s(1));
  return out;
}

std::set<std::string> Store::guide_hashes() {
  Stmt st(rd_, "SELECT DISTINCT hash FROM guides WHERE hash != ''");
  std::set<std::string> out;
  while (st.step()) out.insert(st.s(0));
  return out;
}

void Store::save_training(uint64_t job, uint32_t tile, uint32_t pass, const std::string& records) {
  WriteLock lock(write_mu_);
  Stmt(db_, prepared("INSERT OR REPLACE INTO training(job, pass, tile, data) VALUES(?, ?, ?, ?)"))
      .bind(int64_t(job)).bind(int64_t(pass)).bind(int64_t(tile)).blob(records).step();
}

void Store::for_each_training(uint64_t job, uint32_t pass, const std::function<void(uint32_t, std::string&&)>& fn) {
  Stmt st(rd_, "SELECT tile, data FROM training WHERE job = ? AND pass = ? ORDER BY tile");
  st.bind(int64_t(job)).bind(int64_t(pass));
  while (st.step()) fn(uint32_t(st.i(0)), st.s(1));
}

void Store::for_each_result(uint64_t job, const std::function<void(ResultRow&&)>& fn, bool with_data) {
  Stmt st(rd_, with_data ? "SELECT tile, pass, worker, data FROM results WHERE job = ? ORDER BY pass, tile"
                         : "SELECT tile, pass, worker, '' FROM results WHERE job = ? ORDER BY pass, tile");
  st.bind(int64_t(job));
  while (st.step()) fn(ResultRow{uint32_t(st.i(0)), uint32_t(st.i(1)), uint64_t(st.i(2)), st.s(3)});
}

uint64_t Store::reissued_after_ack(uint64_t job) {
  Stmt st(rd_,
          "SELECT COUNT(*) FROM leases l JOIN results r ON r.job = l.job AND r.pass = l.pass AND r.tile = l.tile "
          "WHERE l.job = ? AND l.seq > r.ack_seq");
  st.bind(int64_t(job)).step();
  return uint64_t(st.i(0));
}

uint64_t Store::leases_issued(uint64_t job) {
  Stmt st(rd_, "SELECT COUNT(*) FROM leases WHERE job = ?");
  st.bind(int64_t(job)).step();
  return uint64_t(st.i(0));
}

LeaseCounts Store::lease_counts(uint64_t job) {
  Stmt st(rd_,
          "SELECT COALESCE(SUM(n), 0), COALESCE(MAX(n), 0) FROM "
          "(SELECT COUNT(*) AS n FROM leases WHERE job = ? GROUP BY pass, tile)");
  st.bind(int64_t(job)).step();
  return {uint64_t(st.i(0)), uint64_t(st.i(1))};
}

std::vector<LeaseRow> Store::open_leases(uint64_t job) {
  Stmt st(rd_,
          "SELECT l.seq, l.tile, l.pass, l.worker FROM leases l WHERE l.job = ? "
          "AND l.seq = (SELECT MAX(m.seq) FROM leases m WHERE m.job = l.job AND m.pass = l.pass AND m.tile = l.tile) "
          "AND NOT EXISTS (SELECT 1 FROM results r WHERE r.job = l.job AND r.pass = l.pass AND r.tile = l.tile)");
  st.bind(int64_t(job));
  std::vector<LeaseRow> rows;
  while (st.step()) rows.push_back({uint64_t(st.i(0)), uint32_t(st.i(1)), uint32_t(st.i(2)), uint64_t(st.i(3))});
  return rows;
}

std::pair<uint64_t, uint64_t> Store::lease_and_result_counts() {
  Stmt st(rd_, "SELECT (SELECT COUNT(*) FROM leases), (SELECT COUNT(*) FROM results)");
  st.step();
  return {uint64_t(st.i(0)), uint64_t(st.i(1))};
}

std::vector<std::pair<uint64_t, uint64_t>> Store::result_bytes(const std::vector<uint64_t>& ids) {
  std::vector<std::pair<uint64_t, uint64_t>> out;
  if (ids.empty()) {
    Stmt st(rd_,
            "SELECT job, SUM(bytes) FROM (SELECT job, LENGTH(data) AS bytes FROM results UNION ALL "
            "SELECT job, LENGTH(data) FROM checkpoints) GROUP BY job");
    while (st.step()) out.emplace_back(uint64_t(st.i(0)), uint64_t(st.i(1)));
    return out;
  }
  for (uint64_t id : ids) {
    Stmt st(rd_,
            "SELECT (SELECT COALESCE(SUM(LENGTH(data)), 0) FROM results WHERE job = ?1) + "
            "(SELECT COALESCE(SUM(LENGTH(data)), 0) FROM checkpoints WHERE job = ?1)");
    st.bind(int64_t(id)).step();
    out.emplace_back(id, uint64_t(st.i(0)));
  }
  return out;
}

void Store::delete_job(uint64_t id, double now) {
  transaction([&] {
    Stmt(db_, "INSERT OR REPLACE INTO expired_jobs(id, name, expired) SELECT id, name, ? FROM jobs WHERE id = ?")
        .bind(now).bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM results WHERE job = ?").bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM checkpoints WHERE job = ?").bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM pass_plans WHERE job = ?").bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM guides WHERE job = ?").bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM training WHERE job = ?").bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM leases WHERE job = ?").bind(int64_t(id)).step();
    Stmt(db_, "DELETE FROM jobs WHERE id = ?").bind(int64_t(id)).step();
  });
}

std::optional<double> Store::expired_job(uint64_t id) {
  Stmt st(rd_, "SELECT expired FROM expired_jobs WHERE id = ?");
  if (!st.bind(int64_t(id)).step()) return std::nullopt;
  return st.d(0);
}

void Store::delete_scene(const std::string& hash) {
  WriteLock lock(write_mu_);
  Stmt st(db_, "DELETE FROM scenes WHERE hash = ?");
  st.bind(hash).step();
}

void Store::incremental_vacuum() {
  WriteLock lock(write_mu_);
  exec("PRAGMA incremental_vacuum");
}

uint64_t Store::add_worker(const WorkerRow& w) {
  WriteLock lock(write_mu_);
  Stmt st(db_,
          "INSERT INTO workers(name, threads, memory, version, isa, registered, last_seen, state) "
          "VALUES(?, ?, ?, ?, ?, ?, ?, 'idle')");
  st.bind(w.name).bind(int64_t(w.threads)).bind(int64_t(w.memory)).bind(w.version).bind(w.isa).bind(w.registered)
      .bind(w.registered).step();
  return uint64_t(sqlite3_last_insert_rowid(db_));
}

std::optional<WorkerRow> Store::worker(uint64_t id) {
  Stmt st(rd_, "SELECT id, name, version, isa, threads, memory, registered FROM workers WHERE id = ?");
  if (!st.bind(int64_t(id)).step()) return std::nullopt;
  return WorkerRow{uint64_t(st.i(0)), st.s(1), st.s(2), st.s(3), int(st.i(4)), uint64_t(st.i(5)), st.d(6)};
}

void Store::touch_worker(uint64_t id, double now, const std::string& state) {
  WriteLock lock(write_mu_);
  Stmt st(db_, "UPDATE workers SET last_seen = ?, state = ? WHERE id = ?");
  st.bind(now).bind(state).bind(int64_t(id)).step();
}

}  // namespace tessera::server
