// One job's work in memory: the pass sequencer (sequence/pass_sequencer.h) that `tessera render`
// runs too, plus what only a farm has: which units are leased and how often, which are being
// committed, which worker delivered each, the digests a second copy is checked against, and the
// checkpoints that stand in for a tile's stored results.
#pragma once

#include "unit_times.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/sha256.h"
#include "tessera/image/image.h"
#include "tessera/render/film.h"
#include "tessera/render/noise_estimate.h"
#include "tessera/sequence/guide_training.h"
#include "tessera/sequence/pass_sequencer.h"
#include "tessera/sequence/photon_program.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace tessera::server {

enum class JobPhase { Queued, Running, Done, Failed, Cancelled };
const char* phase_name(JobPhase p);
bool parse_phase(const std::string& s, JobPhase& out);
inline bool is_terminal(JobPhase p) { return p == JobPhase::Done || p == JobPhase::Failed || p == JobPhase::Cancelled; }

/// Whether the farm can run `program` (Tile and Paths passes into one film or several): what it
/// cannot, or empty.
std::string farm_program_error(const PassProgram& program);

class JobState {
 public:
  JobState(uint64_t id, JobPlan plan, std::string name, int priority, double created);

  uint64_t id() const { return id_; }
  const JobPlan& plan() const { return plan_; }
  const std::string& name() const { return name_; }
  int priority() const { return priority_; }
  double created() const { return created_; }
  const PassSequencer& sequencer() const { return seq_; }

  // Units: the sequencer's, pass-major. A unit is named (index, pass) on the wire and in the store,
  // where the index is its tile in a Tile pass and its range of paths in a Paths pass.
  size_t num_tiles() const { return seq_.num_tiles(); }
  size_t num_passes() const { return seq_.num_passes(); }
  size_t num_units() const { return seq_.num_units(); }
  size_t done_units() const { return seq_.done_units(); }
  uint32_t tile_of(size_t unit) const { return seq_.index_of(unit); }
  uint32_t pass_of(size_t unit) const { return seq_.pass_of(unit); }
  size_t unit(uint32_t tile, uint32_t pass) const { return seq_.unit(pass, tile); }
  /// Whether (index, pass) names a unit of the job.
  bool has_unit(uint32_t index, uint32_t pass) const { return pass < num_passes() && index < seq_.units_in(pass); }
  bool is_tile_unit(size_t unit) const { return seq_.pass(pass_of(unit)).kind == UnitKind::Tile; }
  /// A Tile unit's tile; a Paths unit's result covers the whole window.
  const TileRect& rect(size_t unit) const { return is_tile_unit(unit) ? seq_.tiles()[tile_of(unit)] : plan_.window; }
  /// A Paths unit's light paths.
  std::pair<uint64_t, uint64_t> paths(size_t unit) const {
    const UnitWork w = seq_.work(unit);
    return {w.path_begin, w.path_end};
  }
  uint32_t sample_begin(size_t unit) const { return seq_.pass(pass_of(unit)).sample_begin; }
  uint32_t sample_end(size_t unit) const { return sample_begin(unit) + seq_.pass(pass_of(unit)).samples; }
  /// Samples of the unit (pixels x samples per pixel, or an adaptive pass's counts): its work.
  uint64_t unit_samples(size_t unit) const { return seq_.unit_samples(unit); }
  /// The samples the job will render: all of spp, or those done once it stopped at its target.
  uint64_t total_samples() const { return seq_.planned_samples(); }
  uint64_t done_samples() const { return seq_.done_samples(); }
  /// Samples done of the samples the job will have (1 for a job with none).
  double progress() const { return total_samples() ? double(done_samples()) / double(total_samples()) : 1.0; }
  size_t planned_units() const { return seq_.planned_units(); }
  /// Every planned unit is done and its splats folded into the film.
  bool complete() const { return seq_.complete() && !seq_.films().splats_held(); }

  // A Paths unit's splats are folded a chunk at a time (fold_splats), each chunk under the
  // coordinator's lock, never a whole image-wide result at once.
  bool splats_ready() const { return seq_.films().splats_ready(); }
  size_t fold_splats(size_t max_splats) { return seq_.films().fold_splats(max_splats); }
  bool folding = false;  // a fold task is queued or running

  // Target error: the sequencer stops at a barrier whose estimate is at the target; the decision
  // depends on the film of the passes before it alone, so it is the same however the tiles were
  // rendered, and the same again when the job is rebuilt from its results after a restart.
  bool converged() const { return seq_.stopped(); }
  uint32_t spp_complete() const { return seq_.spp_complete(); }
  NoiseEstimate noise() const { return seq_.noise(); }
  void restore_converged() { seq_.restore_stopped(); }

  // What a lease carries beyond its rectangle: an adaptive pass's counts (a result must hold
  // exactly them) and the guide it renders with.
  std::optional<PassSamples> lease_samples(size_t unit) const { return seq_.work(unit).samples; }
  bool result_fits(size_t unit, const FilmTile& film) const { return seq_.fits(unit, film); }
  std::optional<Lease::Guide> lease_guide(size_t unit) const;
  /// The per-pixel state a tile_state unit starts from (null for any other unit).
  const std::string* lease_tile_state(size_t unit) const { return seq_.work(unit).tile_state; }
  /// The kind of record a unit's records must be, checked before they reach add_result (off the
  /// coordinator's lock): a job whose passes feed point maps has one.
  std::optional<IntegratorType> point_records() const {
    return plan_.points ? std::optional<IntegratorType>(plan_.points->type) : std::nullopt;
  }
  /// Whether a Tile unit's result must carry per-pixel state (sppm's gathers leave it).
  bool tile_leaves_state(size_t unit) const {
    return is_tile_unit(unit) && plan_.points && plan_.points->type == IntegratorType::Sppm;
  }
  [[nodiscard]] bool check_training(size_t unit, std::string_view records, std::string& error) const {
    return seq_.check_records(unit, records, error);
  }

  // Decisions taken at barriers, stored before the passes that depend on them are leased.
  std::vector<PassSequencer::DecidedPass> take_new_plans() { return seq_.take_decided_passes(); }
  std::optional<PassSequencer::MadeArtifact> take_artifact() { return seq_.take_artifact(); }
  void artifact_stored(uint32_t i, std::string hash) { seq_.artifact_stored(i, std::move(hash)); }
  uint32_t guide_iterations() const { return seq_.builder() ? seq_.artifacts_stored() : 0; }
  const GuideTraining* guide() const { return dynamic_cast<const GuideTraining*>(seq_.builder()); }

  // Rebuilding after a restart (sequencer: begin_rebuild).
  void begin_rebuild() { seq_.begin_rebuild(); }
  void end_rebuild() { seq_.end_rebuild(); }
  [[nodiscard]] bool restore_pass_plan(uint32_t pass, std::vector<uint32_t> counts, std::string& error) {
    return seq_.restore_pass_plan(pass, std::move(counts), error);
  }
  bool pass_decided(uint32_t pass) const { return seq_.pass_planned(pass); }
  void restore_artifacts(std::vector<std::string> hashes, std::shared_ptr<const Artifact> latest) {
    seq_.restore_artifacts(std::move(hashes), std::move(latest));
  }
  /// The first pass that feeds an iteration after `iteration` (the number of passes if none):
  /// records of the passes before it are spent once `iteration` is stored.
  uint32_t first_pass_feeding_after(uint32_t iteration) const;
  /// The hash of the point map that storing iteration `iteration` spends (its predecessor, which
  /// no pass gathers from any more), if the job makes point maps.
  std::optional<std::string> spent_by(uint32_t iteration) const {
    if (!plan_.points || iteration == 0 || iteration > seq_.artifacts_stored()) return std::nullopt;
    return seq_.artifact_hash(iteration - 1);
  }
  /// The passes whose stored records go into the artifact made next (a restart mid-training).
  std::vector<uint32_t> passes_feeding_next() const;
  void restore_records(uint32_t pass, uint32_t tile, std::string_view records);

  // Leasing.
  /// A unit that is ready, neither done nor being committed, and not leased: one handed back
  /// (its lease ended without a result), else the first such, pass-major. Amortised O(1): a cursor
  /// passes units leased or done once, and units handed back are kept apart.
  std::optional<size_t> next_unit() const;
  void lease_started(size_t unit) { ++active_leases_[unit]; }
  /// A lease of the unit was issued (not re-adopted): counted per unit, for max_leases_per_unit.
  void lease_issued(size_t unit);
  /// The most leases this process issued for any one unit of the job.
  unsigned max_leases_per_unit() const { return max_leases_per_unit_; }
  /// The unit's result is in or being committed: it is never leased again.
  bool unit_finished(size_t unit) const { return is_done(unit) || is_committing(unit); }
  unsigned active_leases(size_t unit) const { return active_leases_[unit]; }
  void lease_ended(size_t unit);
  bool is_done(size_t unit) const { return seq_.is_done(unit); }
  uint64_t accepted_from(size_t unit) const { return accepted_from_[unit]; }
  /// A result for the unit is being committed: it is not leased again meanwhile, and a second
  /// result is a duplicate. Ended by add_result, or by commit_failed (the unit is open again).
  bool is_committing(size_t unit) const { return committing_[unit] != 0; }
  void start_commit(size_t unit);
  void commit_failed(size_t unit);
  /// The digest of a unit's accepted sums, kept when another copy of it was in flight (also once
  /// the job has ended: that copy's result may still arrive).
  void remember_digest(size_t unit, const Sha256Digest& d) { digests_[unit] = d; }
  const Sha256Digest* digest(size_t unit) const {
    auto it = digests_.find(unit);
    return it == digests_.end() ? nullptr : &it->second;
  }
  /// Adds a verified result (with a training unit's records, checked); false when the unit was
  /// already done (a duplicate).
  bool add_result(size_t unit, FilmTile&& tile, uint64_t worker, std::string_view training = {},
                  std::string tile_state = {});
  /// The same for a Paths unit's splats.
  bool add_splats(size_t unit, SplatSums&& splats, uint64_t worker, std::string_view records = {});
  /// Marks a unit done without its sums (a finished job resumed from its stored image, or a pass a
  /// tile's checkpoint holds).
  void mark_done(size_t unit, uint64_t worker);

  // Checkpoints: a tile's sums over its passes 0..passes-1 (the film's region, which holds them in
  // pass order), stored in place of those passes' results. Taken as passes enter the film; a job is
  // rebuilt from its checkpoints and the results after them, bit for bit, since adding a tile's sums
  // to a zero film reproduces them exactly.
  struct Checkpoint {
    uint32_t tile = 0, from = 0, passes = 0;  // results of passes from..passes-1 become redundant
    uint32_t sample_end = 0;                 // samples per pixel it holds
    std::vector<FilmTile> films;             // the tile's sums in each film (the first with the passes' counters)
    std::string tile_state;                  // what the latest of those passes left (tile_state)
  };
  std::optional<Checkpoint> take_checkpoint(uint32_t tile, uint32_t min_new);
  /// The checkpoint the tile will have once `result` (for `unit`, about to be committed) is in:
  /// when it is the tile's next pass, every pass before it is in a checkpoint and no other result
  /// of the tile is being committed. Stored in the result's place, its bytes never need storing.
  std::optional<Checkpoint> checkpoint_with(size_t unit, const FilmTile& result, const std::string& tile_state) const;
  void checkpoint_stored(uint32_t tile, uint32_t passes) { folded_[tile] = std::max(folded_[tile], passes); }
  /// Passes of the tile in the film (a stored result of an earlier pass is in a checkpoint).
  uint32_t passes_in_film(uint32_t tile) const { return seq_.films().next_pass(tile); }
  void checkpoint_failed(uint32_t tile, uint32_t from) { folded_[tile] = std::min(folded_[tile], from); }
  void restore_checkpoint(uint32_t tile, uint32_t passes, std::vector<FilmTile>&& films, std::string tile_state = {});
  /// Samples per pixel a tile's checkpoint of its passes before `next_pass` holds: the end of the
  /// latest Tile pass among them (Paths passes between them add none of a tile's own).
  uint32_t tile_sample_end(uint32_t next_pass) const;
  /// The Tile passes among passes [from, to).
  std::vector<uint32_t> tile_passes(uint32_t from, uint32_t to) const;

  // The image.
  Image image() const { return seq_.films().image(); }
  void image_rows(Image& img, int row_begin, int row_end) const { seq_.films().image_rows(img, row_begin, row_end); }
  void aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const {
    seq_.films().aov_rows(layer, img, row_begin, row_end);
  }
  uint64_t film_changes() const { return seq_.films().changes(); }
  const Film& film() const { return seq_.films().film(seq_.films().primary_film()); }
  /// The film is allocated when the first result arrives, not at submission: a queue of jobs (a
  /// frame range) costs no film memory until each one renders.
  bool film_allocated() const { return seq_.films().allocated(); }
  /// The image is in memory (the film, or black before any result). A finished job's film is
  /// dropped once its image is on disk (a 1080p film holds 116 MB of sums); the image is then
  /// served from the file.
  bool has_film() const { return !seq_.films().released(); }
  void release_film() {
    seq_.release();
    denoised_preview.reset();
  }
  const RenderCounters& counters() const { return seq_.films().counters(); }
  const std::map<uint64_t, uint64_t>& samples_by_worker() const { return samples_by_worker_; }

  /// Its phase and priority change in its registry (job_registry.h), which orders jobs by them.
  JobPhase phase() const { return phase_; }
  /// Rebuilding, before the job enters its registry: the phase its row stores.
  void restore_phase(JobPhase phase) { phase_ = phase; }

  std::string error;
  double started = 0, finished = 0;
  // Failure bookkeeping: per worker, failures on this job; the reasons, for the job's error text.
  std::map<uint64_t, int> failures_by_worker;
  std::string last_failure;
  uint64_t duplicates = 0;
  UnitTimes unit_times;  // render seconds of its accepted units (the speculation threshold's base)
  uint64_t mismatched = 0;  // duplicates whose sums differed from the accepted result's
  uint64_t result_bytes = 0;  // compressed bytes of the accepted results (the network cost)
  uint64_t lease_bytes = 0;   // JSON bytes of the leases handed out
  size_t lease_job_part_bytes = 0;  // of each lease's job part (0: not measured yet; see protocol.h)
  bool image_pending = false;  // an ended job's image is being written (its film is kept until then)
  // A denoised job whose units are all in: its images are being made (job_denoise.cpp), and then
  // whether they were written (finish_job then only drops the film).
  bool denoise_pending = false;
  bool images_written = false;
  // A running denoised job's preview, denoised (refresh_denoised_preview): the latest made, the
  // film_changes() it was made at, and whether a newer one is being made.
  std::shared_ptr<const Image> denoised_preview;
  uint64_t denoised_preview_changes = 0;
  bool preview_denoise_pending = false;
  // A point-map job's stored maps not yet spent: when their files were written (a spent map's file
  // is removed only if no one wrote it since).
  std::map<uint32_t, std::filesystem::file_time_type> artifacts_written;
  uint64_t latest_map_bytes = 0;  // the latest stored point map's records (job status)

 private:
  Checkpoint film_checkpoint(uint32_t tile) const;
  bool add_unit_result(size_t unit, UnitResult&& result, uint64_t worker);

  friend class JobRegistry;

  uint64_t id_;
  JobPlan plan_;
  std::string name_;
  int priority_;
  JobPhase phase_ = JobPhase::Queued;
  double created_;
  PassSequencer seq_;
  std::vector<uint8_t> committing_;              // per unit
  std::vector<uint16_t> active_leases_;          // per unit
  std::vector<uint16_t> leases_issued_;          // per unit (saturating)
  unsigned max_leases_per_unit_ = 0;
  std::vector<uint64_t> accepted_from_;          // per done unit: the worker its result came from
  std::vector<uint32_t> folded_;                 // per tile: passes in its checkpoint
  std::vector<uint16_t> tile_committing_;        // per tile: results being committed
  std::map<size_t, Sha256Digest> digests_;       // see remember_digest
  mutable size_t cursor_ = 0;                    // units before it were leased or done (next_unit)
  mutable std::set<size_t> returned_;            // units behind the cursor handed back
  std::map<uint64_t, uint64_t> samples_by_worker_;
};

/// The samples per pixel an image of the job holds once finished: the spp reached when it stopped
/// at its target error, else its spp (what the EXR header's tessera_spp says).
inline uint32_t image_spp(const JobState& job) {
  return job.converged() ? job.spp_complete() : uint32_t(job.plan().settings.spp);
}

}  // namespace tessera::server
