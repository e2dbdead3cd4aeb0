// The coordinator's durable state in SQLite (WAL, synchronous=FULL): scenes, jobs, acknowledged
// tile-pass results (as the compressed bytes the worker sent, until a per-tile checkpoint of the
// film's sums holds them), the checkpoints, the lease log and workers.
// A result is committed (fsync'd) before the coordinator acknowledges it, so after kill -9 every
// acknowledged pass is still here. Methods throw StoreError; services map it to 500/507.
//
// Writes go through one connection, one at a time (the coordinator's group commit batches most of
// them in transaction()); reads use a second connection and see committed data only. Safe to call
// from any thread.
#pragma once

#include <cstdint>
#include <functional>
#include <set>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace tessera::server {

struct StoreError : std::runtime_error {
  bool disk_full = false;
  StoreError(const std::string& what, bool full) : std::runtime_error(what), disk_full(full) {}
};

/// A write failed because the disk holding the data directory is full (ENOSPC, EDQUOT,
/// SQLITE_FULL). Services answer 507 with the directory named; nothing half-written is kept.
struct DiskFullError : StoreError {
  std::string data_dir;
  DiskFullError(const std::string& what, std::string dir) : StoreError(what, true), data_dir(std::move(dir)) {}
};

struct JobRow {
  uint64_t id = 0;
  std::string name, plan_json, state, error;
  int priority = 0;
  double created = 0, started = 0, finished = 0;
};

struct WorkerRow {
  uint64_t id = 0;
  std::string name, version = {}, isa = {};
  int threads = 0;
  uint64_t memory = 0;
  double registered = 0;
};

struct LeaseRow {
  uint64_t id = 0;
  uint32_t tile = 0, pass = 0;
  uint64_t worker = 0;
};

struct CheckpointRow {
  uint32_t tile = 0, passes = 0;
  std::string data;
};

struct LeaseCounts {
  uint64_t issued = 0, max_per_unit = 0;
};

struct ResultRow {
  uint32_t tile = 0, pass = 0;
  uint64_t worker = 0;
  std::string data;
};

class Store {
 public:
  /// Opens (creating) `path`; throws StoreError.
  explicit Store(const std::string& path);
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  /// Runs `writes` (calls of the write methods below) in one transaction: all committed with one
  /// fsync, or none (rolled back, and the error rethrown).
  void transaction(const std::function<void()>& writes);

  void add_scene(const std::string& hash, uint64_t bytes, double now);
  bool has_scene(const std::string& hash);

  uint64_t add_job(const std::string& name, const std::string& plan_json, int priority, double now);
  void set_job_state(uint64_t id, const std::string& state, const std::string& error, double started,
                     double finished);
  void set_job_priority(uint64_t id, int priority);
  std::vector<JobRow> jobs();

  /// Logs lease `seq` (ids are chosen by the caller, above last_lease_seq(), and never reused).
  void log_lease(uint64_t seq, uint64_t job, uint32_t tile, uint32_t pass, uint64_t worker, double now);
  /// The largest lease id ever logged (also once its rows were deleted).
  uint64_t last_lease_seq();
  /// The highest worker id registered so far (0 if none).
  uint64_t last_worker_id();
  /// Commits an acknowledged result. False if (job, tile, pass) already had one (a duplicate).
  bool add_result(uint64_t job, uint32_t tile, uint32_t pass, uint64_t worker, std::string_view data,
                  double now);
  /// Stores a tile's checkpoint (its sums over passes 0..passes-1, tile_result.h bytes) and drops
  /// the bytes of the tile's results in `held` (its Tile passes from..passes-1, which it now holds:
  /// a Paths pass's unit of the same index is not the tile's); their rows stay.
  void save_checkpoint(uint64_t job, uint32_t tile, uint32_t passes, const std::string& data,
                       const std::vector<uint32_t>& held);
  void for_each_checkpoint(uint64_t job, const std::function<void(CheckpointRow&&)>& fn);
  /// Calls `fn` for every result of `job`, ordered by pass then tile (`with_data`: the bytes too;
  /// empty for a pass a checkpoint holds).
  void for_each_result(uint64_t job, const std::function<void(ResultRow&&)>& fn, bool with_data = true);
  /// Stores an adaptive pass's per-pixel sample counts (sample_counts.h bytes); replaces a copy.
  void save_pass_plan(uint64_t job, uint32_t pass, const std::string& data);
  /// Calls `fn(pass, bytes)` for every stored pass plan of `job`, in pass order.
  void for_each_pass_plan(uint64_t job, const std::function<void(uint32_t, std::string&&)>& fn);
  /// A job's artifact of iteration `iteration` is stored (its file) under `hash`; the training
  /// records of passes before `fed_before` (the passes that fed it or an earlier one) are no
  /// longer needed and are dropped.
  void save_guide(uint64_t job, uint32_t iteration, const std::string& hash, uint32_t fed_before);
  /// Iteration `iteration` of the job's artifacts is needed by no pass any more (a point map whose
  /// gathers are done): its row keeps its place, without its hash, and its file may go.
  void spend_guide(uint64_t job, uint32_t iteration);
  /// Whether any job's row names the artifact `hash`.
  bool guide_named(const std::string& hash);
  /// The job's stored trees' hashes, by iteration.
  std::vector<std::string> guides(uint64_t job);
  /// Every job's (a guide file no job names is deleted by retention).
  std::set<std::string> guide_hashes();
  /// Stores a training unit's records (guiding/tree_io.h bytes) until its pass's tree is stored.
  void save_training(uint64_t job, uint32_t tile, uint32_t pass, const std::string& records);
  /// Calls `fn(tile, bytes)` for each stored training record of the job's pass `pass`, by tile.
  void for_each_training(uint64_t job, uint32_t pass, const std::function<void(uint32_t, std::string&&)>& fn);
  /// Leases issued for a pass after that pass had been acknowledged (should be 0: the measure the
  /// restart test reads).
  uint64_t reissued_after_ack(uint64_t job);
  uint64_t leases_issued(uint64_t job);
  /// The job's leases and the most of them for any one unit, in one pass over its lease log.
  LeaseCounts lease_counts(uint64_t job);
  /// Each unit's newest lease when the unit has no result: the work in flight when the previous
  /// process stopped.
  std::vector<LeaseRow> open_leases(uint64_t job);
  /// Leases logged and results stored, over every job still here (the /metrics counters' start).
  std::pair<uint64_t, uint64_t> lease_and_result_counts();

  // Retention (retention.cpp): sizes, deletion of a finished job, tombstones for its id.
  /// Bytes of stored result and checkpoint data per job (only the jobs in `ids`, or every job when
  /// empty).
  std::vector<std::pair<uint64_t, uint64_t>> result_bytes(const std::vector<uint64_t>& ids = {});
  /// Deletes a job's results, lease log and row in one transaction, leaving a tombstone (its id,
  /// name and when it expired) so its status can say why it is gone.
  void delete_job(uint64_t id, double now);
  /// When job `id` was deleted by retention, if it was.
  std::optional<double> expired_job(uint64_t id);
  void delete_scene(const std::string& hash);
  /// Returns freed pages to the file system (databases created with auto_vacuum=INCREMENTAL;
  /// older ones keep their size and reuse the pages).
  void incremental_vacuum();

  uint64_t add_worker(const WorkerRow& w);
  std::optional<WorkerRow> worker(uint64_t id);
  void touch_worker(uint64_t id, double now, const std::string& state);

 private:
  using WriteLock = std::lock_guard<std::recursive_mutex>;
  void exec(const char* sql);
  /// The write connection's statement for `sql` (a string literal: keyed by its address),
  /// prepared once; used under write_mu_ only.
  sqlite3_stmt* prepared(const char* sql);
  sqlite3* db_ = nullptr;  // writes
  sqlite3* rd_ = nullptr;  // reads
  std::recursive_mutex write_mu_;  // a transaction's writes are never interleaved with another's
  std::unordered_map<const char*, sqlite3_stmt*> prepared_;
};

}  // namespace tessera::server
