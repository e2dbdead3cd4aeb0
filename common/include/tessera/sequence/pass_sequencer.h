// The pass sequencer: runs a PassProgram (pass_program.h), the one place that decides which units
// of a render may be rendered, what each is given, and what happens to its result. `tessera
// render` (sequence/renderer.h) and the farm's coordinator (server/src/job_state.h) both drive
// one, so a local render and a farm job are the same by construction; only who renders a unit,
// and when its result arrives, differ.
//
// The contract:
// - Units. Pass p has units_in(p) units, numbered pass-major: a Tile pass one per tile (row-major
//   tiles of `tile_size`), a Paths pass one per range of `paths_per_unit` light paths. work(u)
//   says what unit u renders: its rectangle and per-pixel samples, or its range of paths; the
//   artifact it renders with and the one its records feed; the per-pixel state it starts from.
// - Results. add_result() takes a unit's result once (a second is a duplicate): a Tile unit's
//   FilmTile covers its tile, a Paths unit's SplatSums the whole window. They enter their films
//   in the fixed order film_assembler.h describes, so the image does not depend on the order
//   results arrive in, on the thread or machine that made them, or on the tiling.
// - Barriers. A pass opens when every pass before it is open and, if it is a barrier, every pass
//   before it is complete; then, in this order, the render stops if the pass may stop and the
//   estimate is at the target; its adaptive counts are decided from the film; the artifact it
//   renders with is built. A pass whose artifact is built opens only once that artifact is stored
//   (artifact_stored: at once locally, once durable on the farm).
// - Artifacts. Built by the program's ArtifactBuilder at the barrier (iteration 0 at the start),
//   from the records of the units that feed them; take_artifact() hands each new one out once,
//   for the caller to store and, on the farm, to hash and name in the leases that render with it.
// - State. A tile_state pass's unit (p, t) is ready only once unit t of the latest Tile pass
//   before p is done, and starts from the per-pixel state that result left (UnitResult::tile_state).
// - Restarts (the farm): begin_rebuild() holds every pass shut while stored decisions, artifacts,
//   checkpoints and results are restored; end_rebuild() then opens what they allow, so a decision
//   taken before a restart is recognised rather than taken again.
//
// Not thread-safe: a local render serialises its calls under one mutex, the coordinator under its
// job registry's.
#pragma once

#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"
#include "tessera/sequence/adaptive_plans.h"
#include "tessera/sequence/artifact.h"
#include "tessera/sequence/film_assembler.h"
#include "tessera/sequence/pass_program.h"
#include "tessera/sequence/splat_sums.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

/// The render's frame: its window on the full film, how it is tiled, whether AOVs are summed.
struct SequenceFrame {
  TileRect window;
  int full_width = 0, full_height = 0;
  int tile_size = 32;
  bool aovs = false;
};

/// What a unit renders.
struct UnitWork {
  uint32_t pass = 0, index = 0;   // index: the tile (Tile) or the range (Paths) within the pass
  UnitKind kind = UnitKind::Tile;
  TileRect rect;                  // Tile: its pixels
  /// Tile: the pass's nominal samples of each pixel; an adaptive pass's own are in `samples` (set
  /// once the pass is decided, while it is the latest decided pass: when its units may run).
  uint32_t sample_begin = 0, sample_end = 0;
  std::optional<PassSamples> samples;
  uint64_t path_begin = 0, path_end = 0;  // Paths: its light paths
  std::optional<uint32_t> uses, feeds;    // artifact iterations (PassSpec)
  const std::string* tile_state = nullptr;  // tile_state: what that unit left (PassSpec::tile_state)
};

/// A unit's result.
struct UnitResult {
  FilmTile tile;           // Tile
  SplatSums splats;        // Paths
  std::string records;     // for the artifact the unit feeds (empty if it feeds none)
  std::string tile_state;  // Tile: per-pixel state the tile's next pass starts from
};

class PassSequencer {
 public:
  /// `builder` makes the program's artifacts (needed iff a pass uses or feeds one). Throws
  /// std::invalid_argument naming the flaw of an unsound program (program_error).
  PassSequencer(PassProgram program, const SequenceFrame& frame, std::unique_ptr<ArtifactBuilder> builder = nullptr);

  const PassProgram& program() const { return program_; }
  const SequenceFrame& frame() const { return frame_; }
  size_t num_passes() const { return program_.passes.size(); }
  size_t num_tiles() const { return tiles_.size(); }
  const std::vector<TileRect>& tiles() const { return tiles_; }
  const PassSpec& pass(uint32_t p) const { return program_.passes[p]; }
  uint32_t units_in(uint32_t pass) const { return unit_begin_[pass + 1] - unit_begin_[pass]; }
  size_t num_units() const { return unit_begin_.back(); }
  size_t unit(uint32_t pass, uint32_t index) const { return unit_begin_[pass] + index; }
  /// The first unit of `pass` (num_units() for pass num_passes()).
  size_t first_unit(uint32_t pass) const { return unit_begin_[pass]; }
  uint32_t pass_of(size_t unit) const;
  uint32_t index_of(size_t unit) const { return uint32_t(unit - unit_begin_[pass_of(unit)]); }
  UnitWork work(size_t unit) const;
  /// The unit's samples: pixel samples of a Tile unit (its adaptive counts once decided), paths of
  /// a Paths unit.
  uint64_t unit_samples(size_t unit) const;
  /// Samples of the whole render (all of spp; once stopped at the target, those done).
  uint64_t planned_samples() const { return stopped_ ? done_samples_ : total_samples_; }
  uint64_t done_samples() const { return done_samples_; }

  // Progress through the program.
  /// Passes [0, open_passes()) have units that may be rendered.
  size_t open_passes() const { return open_passes_; }
  /// Open, not done, and (tile_state) the unit whose state it starts from done.
  bool ready(size_t unit) const;
  bool is_done(size_t unit) const { return done_[unit]; }
  size_t done_units() const { return done_units_; }
  /// Units the render will have (fewer than num_units() once it stopped at its target).
  size_t planned_units() const { return stopped_ ? done_units_ : num_units(); }
  /// Every planned unit is done.
  bool complete() const { return stopped_ || done_units_ == num_units(); }
  /// It stopped at a barrier whose estimate reached the target.
  bool stopped() const { return stopped_; }
  /// Samples per pixel of the passes every tile has.
  uint32_t spp_complete() const;
  /// The first pass not yet complete.
  size_t complete_passes() const { return complete_passes_; }

  // Results.
  /// Whether a result's records are what its unit feeds (checked, not added).
  [[nodiscard]] bool check_records(size_t unit, std::string_view records, std::string& error) const;
  /// Whether a Tile result's per-pixel sample counts are its unit's (an adaptive pass's plan).
  bool fits(size_t unit, const FilmTile& tile) const;
  /// Whether the pass's per-pixel samples are known (not adaptive, or decided).
  bool pass_planned(uint32_t pass) const { return !program_.passes[pass].adaptive || plans_->decided(pass); }
  /// Takes a unit's result (records checked): false for a duplicate. Then opens what it allows.
  bool add_result(size_t unit, UnitResult&& result);
  /// Marks a unit done without its result (a finished farm job, or a pass a checkpoint holds).
  void mark_done(size_t unit);

  // Barrier decisions, for the farm to store before the passes that depend on them open.
  struct DecidedPass {
    uint32_t pass = 0;
    std::vector<uint32_t> counts;  // row-major over the window
    double seconds = 0;            // deciding took
  };
  /// Adaptive passes decided since the last call.
  std::vector<DecidedPass> take_decided_passes() { return std::move(decided_); }
  struct MadeArtifact {
    uint32_t iteration = 0;
    std::shared_ptr<const Artifact> artifact;
    double seconds = 0;  // building took
  };
  /// The newest artifact while it is not handed out yet, once.
  std::optional<MadeArtifact> take_artifact();
  /// Iteration `i` is stored under `hash` (in order; "" locally): the passes that use it may open.
  void artifact_stored(uint32_t i, std::string hash);
  /// The artifact of iteration `i` (null before it is made, or once released) and its hash.
  const Artifact* artifact(uint32_t i) const;
  const std::string& artifact_hash(uint32_t i) const { return hashes_.at(i); }
  uint32_t artifacts_stored() const { return uint32_t(hashes_.size()); }
  ArtifactBuilder* builder() const { return builder_.get(); }

  // Films.
  const FilmAssembler& films() const { return films_; }
  FilmAssembler& films() { return films_; }
  /// The estimate over the image now (cached until the films change).
  NoiseEstimate noise() const;

  // Restarts.
  void begin_rebuild() { rebuilding_ = true; }
  void end_rebuild();
  [[nodiscard]] bool restore_pass_plan(uint32_t pass, std::vector<uint32_t> counts, std::string& error);
  /// The stored artifacts' hashes in order and the latest one, decoded; records for the next follow.
  void restore_artifacts(std::vector<std::string> hashes, std::shared_ptr<const Artifact> latest);
  void restore_stopped() { stopped_ = true; }
  /// A tile's per-pixel state as its latest Tile pass before `next_pass` left it (a checkpoint
  /// holds that pass, whose own result is not stored); a no-op in a program without state.
  void restore_tile_state(uint32_t tile, uint32_t next_pass, std::string state);
  /// The state restore_tile_state() restores: the tile's latest Tile pass's before `next_pass`
  /// (empty in a program without state, or before that pass is done).
  const std::string& tile_state(uint32_t tile, uint32_t next_pass) const;
  /// Frees films, artifacts and plans of a render whose image is written.
  void release();

 private:
  void advance();
  /// The Tile pass a tile_state pass's units start from: the latest before it.
  uint32_t state_pass(uint32_t pass) const;
  size_t state_unit(uint32_t tile, uint32_t next_pass) const;
  bool at_barrier_decided_before(uint32_t pass) const;
  bool open_barrier(uint32_t pass);
  void build_artifact(uint32_t iteration);
  std::optional<uint32_t> first_user(uint32_t iteration) const;

  PassProgram program_;
  SequenceFrame frame_;
  std::vector<TileRect> tiles_;
  std::vector<size_t> unit_begin_;  // per pass, and the total at the end
  std::unique_ptr<ArtifactBuilder> builder_;
  std::optional<AdaptivePlans> plans_;
  FilmAssembler films_;
  std::vector<uint8_t> done_;
  std::vector<uint32_t> pass_done_;  // per pass: units done
  std::vector<std::string> tile_states_;  // per Tile unit (a later tile_state pass starts from it)
  size_t done_units_ = 0, open_passes_ = 0, complete_passes_ = 0;
  uint64_t total_samples_ = 0, done_samples_ = 0;
  bool stopped_ = false, rebuilding_ = false;
  std::vector<DecidedPass> decided_;
  std::vector<std::shared_ptr<const Artifact>> artifacts_;  // per built iteration (the latest kept)
  std::vector<double> build_seconds_;
  size_t handed_out_ = 0;             // artifacts taken so far
  std::vector<std::string> hashes_;   // per stored iteration
  mutable std::optional<NoiseEstimate> noise_;
  mutable uint64_t noise_changes_ = 0;
};

}  // namespace tessera
