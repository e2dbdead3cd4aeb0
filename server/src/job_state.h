// One job's work in memory: its units (tile x pass), which are leased or done, and the Film the
// finished passes are added to, each tile's passes in pass order.
#pragma once

#include "tessera/farm/job_scene.h"
#include "tessera/farm/sha256.h"
#include "job_guide.h"
#include "pass_plans.h"
#include "tessera/image/image.h"
#include "tessera/render/film.h"
#include "tessera/render/noise_estimate.h"

#include <algorithm>
#include <cstdint>
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

class JobState {
 public:
  JobState(uint64_t id, JobPlan plan, std::string name, int priority, double created);

  uint64_t id() const { return id_; }
  const JobPlan& plan() const { return plan_; }
  const std::string& name() const { return name_; }
  int priority() const { return priority_; }
  double created() const { return created_; }

  size_t num_tiles() const { return tiles_.size(); }
  size_t num_passes() const { return passes_.size(); }
  size_t num_units() const { return tiles_.size() * passes_.size(); }
  size_t done_units() const { return done_units_; }
  uint32_t tile_of(size_t unit) const { return uint32_t(unit % tiles_.size()); }
  uint32_t pass_of(size_t unit) const { return uint32_t(unit / tiles_.size()); }
  size_t unit(uint32_t tile, uint32_t pass) const { return size_t(pass) * tiles_.size() + tile; }
  const TileRect& rect(size_t unit) const { return tiles_[tile_of(unit)]; }
  uint32_t sample_begin(size_t unit) const { return pass_begin_[pass_of(unit)]; }
  uint32_t sample_end(size_t unit) const { return pass_begin_[pass_of(unit)] + passes_[pass_of(unit)]; }
  /// Samples of the unit (pixels x samples per pixel, or an adaptive pass's counts): its work.
  uint64_t unit_samples(size_t unit) const;
  /// The samples the job will render: all of spp, or those done once it stopped at its target.
  uint64_t total_samples() const { return converged_ ? done_samples_ : total_samples_; }
  uint64_t done_samples() const { return done_samples_; }
  /// Samples done of the samples the job will have (1 for a job with none).
  double progress() const { return total_samples() ? double(done_samples_) / double(total_samples()) : 1.0; }
  /// Units the job will render (fewer than num_units() once it stopped at its target error).
  size_t planned_units() const { return converged_ ? done_units_ : num_units(); }
  /// Every planned unit is done.
  bool complete() const { return converged_ || done_units_ == num_units(); }

  // Target error (settings.target_error > 0): pass p+1 is leased only once every tile has pass p
  // and the estimate over exactly those passes is above the target. The decision depends on the
  // film of passes 0..p alone, so it is the same however the tiles were rendered, and the same
  // again when the job is rebuilt from its results after a restart.
  bool converged() const { return converged_; }
  /// Samples per pixel of the passes every tile has.
  uint32_t spp_complete() const { return complete_passes_ ? pass_begin_[complete_passes_ - 1] + passes_[complete_passes_ - 1] : 0; }
  /// The estimate over the film now (cached until the next result); +inf before 2 samples a pixel.
  NoiseEstimate noise() const;
  /// A finished job resumed without its film that had stopped at its target.
  void restore_converged() { converged_ = true; }

  // Adaptive sampling (settings.adaptive): passes from PassPlans::first_barrier() open one at a
  // time, each once every tile has the passes before it, with per-pixel counts decided then from
  // the film (pass_plans.h). A lease of such a pass carries its tile's counts; a result must hold
  // exactly them.
  /// The unit's per-pixel samples when its pass is adaptive (else empty: every pixel takes
  /// [sample_begin, sample_end)).
  std::optional<PassSamples> lease_samples(size_t unit) const;
  /// Whether a result's per-pixel sample counts are those of its unit.
  bool result_fits(size_t unit, const FilmTile& film) const;
  /// Whether the pass's samples are decided (its units may exist).
  bool pass_decided(uint32_t pass) const { return !plans_ || plans_->decided(pass); }
  struct DecidedPass {
    uint32_t pass = 0;
    std::vector<uint32_t> counts;  // row-major over the window
    double seconds = 0;            // deciding took (at the barrier, under the coordinator's lock)
  };
  /// Adaptive passes decided since the last call: stored before any of their units is leased.
  std::vector<DecidedPass> take_new_plans() { return std::move(new_plans_); }
  // Path guiding (plan().guide): see job_guide.h. A lease of a pass that samples or trains names
  // the guide it renders with; a training result carries records that go into the next tree.
  /// The guide the unit renders with (when its pass samples or trains).
  std::optional<Lease::Guide> lease_guide(size_t unit) const;
  /// Whether a result's training records are what its unit should carry (checked, not added).
  [[nodiscard]] bool check_training(size_t unit, std::string_view records, std::string& error) const;
  /// The guided job's tree made at a barrier and not yet stored, once (job_guide.h).
  std::optional<std::pair<uint32_t, std::shared_ptr<const SpatialTree>>> take_tree_to_store() {
    return guide_ ? guide_->take_tree_to_store() : std::nullopt;
  }
  /// Iteration `i`'s tree is stored under `hash`: passes that render with it may open.
  void guide_stored(uint32_t i, std::string hash);
  /// The guided job's trees so far, and its latest tree's size (0 without guiding).
  uint32_t guide_iterations() const;
  const JobGuide* guide() const { return guide_ ? &*guide_ : nullptr; }
  /// Rebuilding: the stored trees' hashes in order and the latest tree, then the training
  /// records stored for the pass it trains next (before end_rebuild).
  void restore_guide(std::vector<std::string> hashes, std::shared_ptr<const SpatialTree> latest) {
    guide_->restore(std::move(hashes), std::move(latest));
  }
  void restore_training(std::string_view records) { guide_->add_records(records); }

  /// Rebuilding: an adaptive pass's stored counts, in pass order, before any result.
  [[nodiscard]] bool restore_pass_plan(uint32_t pass, std::vector<uint32_t> counts, std::string& error);
  /// While rebuilding from the store, no pass opens: once every stored result is in (end_rebuild),
  /// a decision taken before a restart is recognised by its units or stored counts, rather than
  /// taken again from a film its checkpoints may have filled with later passes.
  void begin_rebuild() { rebuilding_ = true; }
  void end_rebuild() {
    rebuilding_ = false;
    advance_passes();
  }

  /// The first unit, pass-major, that is neither done nor leased and that `worker` may take.
  std::optional<size_t> next_unit() const;
  void lease_started(size_t unit) { ++active_leases_[unit]; }
  /// Leases of the unit in flight.
  unsigned active_leases(size_t unit) const { return active_leases_[unit]; }
  void lease_ended(size_t unit);
  bool is_done(size_t unit) const { return done_[unit] == kDone; }
  /// The worker whose result of a done unit was accepted.
  uint64_t accepted_from(size_t unit) const { return accepted_from_[unit]; }
  /// A result for the unit is being committed: it is not leased again meanwhile, and a second
  /// result is a duplicate. Ended by add_result, or by commit_failed (the unit is open again).
  bool is_committing(size_t unit) const { return done_[unit] == kCommitting; }
  void start_commit(size_t unit) {
    done_[unit] = kCommitting;
    ++tile_committing_[tile_of(unit)];
  }
  void commit_failed(size_t unit) {
    if (done_[unit] == kCommitting) {
      done_[unit] = kOpen;
      --tile_committing_[tile_of(unit)];
    }
    digests_.erase(unit);
  }
  /// The digest of a unit's accepted sums, kept when another copy of it was in flight (also once
  /// the job has ended: that copy's result may still arrive).
  void remember_digest(size_t unit, const Sha256Digest& d) { digests_[unit] = d; }
  const Sha256Digest* digest(size_t unit) const {
    auto it = digests_.find(unit);
    return it == digests_.end() ? nullptr : &it->second;
  }
  /// Adds a verified result (with a training unit's records, checked); false when the unit was
  /// already done (a duplicate).
  bool add_result(size_t unit, FilmTile&& tile, uint64_t worker, std::string_view training = {});
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
    FilmTile sums;                           // (with the counters of those passes)
  };
  /// The tile's checkpoint once at least `min_new` passes entered the film since the last one.
  std::optional<Checkpoint> take_checkpoint(uint32_t tile, uint32_t min_new);
  /// The checkpoint the tile will have once `result` (for `unit`, about to be committed) is in:
  /// when it is the tile's next pass, every pass before it is in a checkpoint and no other result
  /// of the tile is being committed. Stored in the result's place, its bytes never need storing.
  std::optional<Checkpoint> checkpoint_with(size_t unit, const FilmTile& result) const;
  /// That checkpoint was stored (with the result, which add_result then adds to the film).
  void checkpoint_stored(uint32_t tile, uint32_t passes) { folded_[tile] = std::max(folded_[tile], passes); }
  /// Passes of the tile in the film (a stored result of an earlier pass is in a checkpoint).
  uint32_t passes_in_film(uint32_t tile) const { return next_pass_[tile]; }
  /// The checkpoint was not stored: its passes are checkpointed again next time.
  void checkpoint_failed(uint32_t tile, uint32_t from) { folded_[tile] = std::min(folded_[tile], from); }
  /// Rebuilding: the tile's sums over its first `passes` passes (their units are marked done from
  /// their rows, before or after).
  void restore_checkpoint(uint32_t tile, uint32_t passes, FilmTile&& sums);

  /// Mean radiance over the film window (zero where no pass has arrived). Only with has_film().
  Image image() const;
  /// Rows [row_begin, row_end) of image() into `img` (of the window's size). Only with has_film().
  void image_rows(Image& img, int row_begin, int row_end) const;
  /// The same for an AOV layer (render/aov.h) of a denoised job's film.
  void aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const;
  /// Counts every change of the film's sums (a result or checkpoint added).
  uint64_t film_changes() const { return film_changes_; }
  /// The sums so far; only once a result has arrived (film_allocated()).
  const Film& film() const { return *film_; }
  /// The film is allocated when the first result arrives, not at submission: a queue of jobs (a
  /// frame range) costs no film memory until each one renders.
  bool film_allocated() const { return film_ != nullptr; }
  /// The image is in memory (the film, or black before any result). A finished job's film is
  /// dropped once its image is on disk (a 1080p film holds 116 MB of sums); the image is then
  /// served from the file.
  bool has_film() const { return !film_released_; }
  void release_film() {
    if (film_) (void)noise();  // kept for the finished job's status
    film_.reset();
    film_released_ = true;
    denoised_preview.reset();
    if (plans_) plans_->release_pixels();
    if (guide_) guide_->release_trees();
    waiting_.clear();
  }
  const RenderCounters& counters() const { return counters_; }
  const std::map<uint64_t, uint64_t>& samples_by_worker() const { return samples_by_worker_; }

  void set_priority(int p) { priority_ = p; }

  JobPhase phase = JobPhase::Queued;
  std::string error;
  double started = 0, finished = 0;
  // Failure bookkeeping: per worker, failures on this job; the reasons, for the job's error text.
  std::map<uint64_t, int> failures_by_worker;
  std::string last_failure;
  uint64_t duplicates = 0;
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

 private:
  uint64_t id_;
  JobPlan plan_;
  std::string name_;
  int priority_;
  double created_;
  std::vector<TileRect> tiles_;
  std::vector<uint32_t> passes_, pass_begin_;
  enum : uint8_t { kOpen, kDone, kCommitting };
  std::vector<uint8_t> done_;  // per unit: kOpen, kDone or kCommitting
  std::vector<uint16_t> active_leases_;
  std::vector<uint64_t> accepted_from_;  // per done unit: the worker its result came from
  std::vector<uint32_t> next_pass_;              // per tile: passes already in the film
  std::vector<uint32_t> folded_;                 // per tile: passes in its checkpoint
  std::vector<uint16_t> tile_committing_;        // per tile: results being committed
  std::vector<RenderCounters> tile_counters_;    // per tile: counters of the passes in the film
  std::map<size_t, FilmTile> waiting_;           // results that arrived before an earlier pass
  std::map<size_t, Sha256Digest> digests_;       // see remember_digest
  void advance_passes();
  bool pass_decided_before(uint32_t pass) const;
  Checkpoint film_checkpoint(uint32_t tile) const;
  void allocate_film();  // on the first result or checkpoint (with AOV sums for a denoised job)

  size_t done_units_ = 0, first_open_ = 0;
  std::vector<uint32_t> pass_done_;  // per pass: tiles that have it
  size_t open_passes_ = 0;           // passes that may be leased
  size_t complete_passes_ = 0;       // passes every tile has
  bool converged_ = false;
  std::optional<PassPlans> plans_;  // adaptive jobs
  std::optional<JobGuide> guide_;   // guided jobs
  bool at_barrier(uint32_t pass) const;
  bool in_film(uint32_t pass) const { return !guide_ || !guide_->discards(pass); }
  std::vector<DecidedPass> new_plans_;
  bool rebuilding_ = false;
  mutable std::optional<NoiseEstimate> noise_;  // for done_units_ == noise_units_
  mutable size_t noise_units_ = 0;
  uint64_t total_samples_ = 0, done_samples_ = 0;
  std::map<uint64_t, uint64_t> samples_by_worker_;
  std::unique_ptr<Film> film_;
  bool film_released_ = false;
  uint64_t film_changes_ = 0;
  RenderCounters counters_;
};

/// SHA-256 of a result's pixel sums: what two renders of one unit must agree on (the worker's
/// timing in the result bytes differs).
inline Sha256Digest tile_digest(const FilmTile& film) {
  return sha256(film.pixels().data(), film.pixels().size() * sizeof(PixelSums));
}

/// The samples per pixel an image of the job holds once finished: the spp reached when it stopped
/// at its target error, else its spp (what the EXR header's tessera_spp says).
inline uint32_t image_spp(const JobState& job) {
  return job.converged() ? job.spp_complete() : uint32_t(job.plan().settings.spp);
}

}  // namespace tessera::server
