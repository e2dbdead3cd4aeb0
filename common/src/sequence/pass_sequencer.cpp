#include "tessera/sequence/pass_sequencer.h"

#include "tessera/core/check.h"
#include "tessera/sequence/pass_schedule.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace tessera {

namespace {

bool uses_artifacts(const PassProgram& program) {
  return std::any_of(program.passes.begin(), program.passes.end(),
                     [](const PassSpec& p) { return p.uses || p.feeds; });
}

}  // namespace

PassSequencer::PassSequencer(PassProgram program, const SequenceFrame& frame, std::unique_ptr<ArtifactBuilder> builder)
    : program_(std::move(program)), frame_(frame), tiles_(make_tiles(frame.window, frame.tile_size)),
      builder_(std::move(builder)),
      films_(program_, tiles_, frame.window, frame.full_width, frame.full_height, frame.aovs) {
  if (std::string e = program_error(program_); !e.empty()) throw std::invalid_argument("pass program: " + e);
  if (uses_artifacts(program_) != (builder_ != nullptr))
    throw std::invalid_argument("pass program: artifacts need a builder, and a builder artifacts");
  const uint64_t pixels = uint64_t(frame.window.area());
  unit_begin_.push_back(0);
  for (const PassSpec& p : program_.passes) {
    const uint64_t paths = pass_paths(p, pixels);
    const size_t units = p.kind == UnitKind::Tile ? tiles_.size()
                                                 : size_t((paths + program_.paths_per_unit - 1) / program_.paths_per_unit);
    unit_begin_.push_back(unit_begin_.back() + units);
    total_samples_ += pixels * p.samples;  // (a photon pass has none)
  }
  done_.assign(num_units(), 0);
  pass_done_.assign(num_passes(), 0);
  if (std::any_of(program_.passes.begin(), program_.passes.end(), [](const PassSpec& p) { return p.tile_state; }))
    tile_states_.resize(num_units());
  if (std::any_of(program_.passes.begin(), program_.passes.end(), [](const PassSpec& p) { return p.adaptive; }))
    plans_.emplace(frame.window, tiles_, program_);
  // (An iteration 0 that a pass feeds is made at its first user's barrier, like any later one.)
  const bool fed0 = std::any_of(program_.passes.begin(), program_.passes.end(), [](const PassSpec& p) { return p.feeds == 0u; });
  if (builder_ && first_user(0) && !fed0) build_artifact(0);
  advance();
}

uint32_t PassSequencer::pass_of(size_t unit) const {
  TESSERA_DCHECK(unit < num_units());
  return uint32_t(std::upper_bound(unit_begin_.begin(), unit_begin_.end(), unit) - unit_begin_.begin() - 1);
}

UnitWork PassSequencer::work(size_t unit) const {
  UnitWork w;
  w.pass = pass_of(unit);
  w.index = uint32_t(unit - unit_begin_[w.pass]);
  const PassSpec& spec = program_.passes[w.pass];
  w.kind = spec.kind;
  w.uses = spec.uses;
  w.feeds = spec.feeds;
  w.sample_begin = spec.sample_begin;
  if (spec.kind == UnitKind::Paths) {
    const uint64_t first = spec.photons > 0 ? 0 : uint64_t(spec.sample_begin) * uint64_t(frame_.window.area());
    const uint64_t end = first + pass_paths(spec, uint64_t(frame_.window.area()));
    w.path_begin = first + uint64_t(w.index) * program_.paths_per_unit;
    w.path_end = std::min(end, w.path_begin + program_.paths_per_unit);
    return w;
  }
  w.rect = tiles_[w.index];
  w.sample_begin = spec.sample_begin;
  w.sample_end = spec.sample_begin + spec.samples;
  if (spec.adaptive && plans_->is_latest(w.pass)) w.samples = plans_->tile_samples(w.index, w.pass);
  if (spec.tile_state) w.tile_state = &tile_states_[unit_begin_[state_pass(w.pass)] + w.index];
  return w;
}

uint64_t PassSequencer::unit_samples(size_t unit) const {
  const uint32_t p = pass_of(unit), i = uint32_t(unit - unit_begin_[p]);
  const PassSpec& spec = program_.passes[p];
  if (spec.kind == UnitKind::Paths) {
    if (spec.photons > 0) return 0;  // (photons are not samples of pixels)
    const UnitWork w = work(unit);
    return w.path_end - w.path_begin;
  }
  if (spec.adaptive && plans_->decided(p)) return plans_->samples(i, p);
  return uint64_t(tiles_[i].area()) * spec.samples;
}

bool PassSequencer::ready(size_t unit) const {
  if (stopped_ || done_[unit]) return false;
  const uint32_t p = pass_of(unit);
  if (p >= open_passes_) return false;
  return !program_.passes[p].tile_state || done_[unit_begin_[state_pass(p)] + (unit - unit_begin_[p])];
}

uint32_t PassSequencer::state_pass(uint32_t pass) const {
  uint32_t q = pass;
  while (q > 0 && program_.passes[--q].kind != UnitKind::Tile) {
  }
  return q;
}

uint32_t PassSequencer::spp_complete() const {
  if (complete_passes_ == 0) return 0;
  const PassSpec& last = program_.passes[complete_passes_ - 1];
  return last.sample_begin + last.samples;
}

bool PassSequencer::check_records(size_t unit, std::string_view records, std::string& error) const {
  const PassSpec& spec = program_.passes[pass_of(unit)];
  if (!spec.feeds) {
    if (records.empty()) return true;
    error = "training records for a pass that feeds no artifact";
    return false;
  }
  return builder_->check_records(*spec.feeds, records, error);
}

bool PassSequencer::fits(size_t unit, const FilmTile& tile) const {
  const uint32_t p = pass_of(unit);
  if (!program_.passes[p].adaptive) return true;
  return plans_->matches(uint32_t(unit - unit_begin_[p]), p, tile);
}

void PassSequencer::mark_done(size_t unit) {
  if (done_[unit]) return;
  done_[unit] = 1;
  ++done_units_;
  ++pass_done_[pass_of(unit)];
  done_samples_ += unit_samples(unit);
  while (complete_passes_ < num_passes() && pass_done_[complete_passes_] == units_in(uint32_t(complete_passes_)))
    ++complete_passes_;
}

bool PassSequencer::add_result(size_t unit, UnitResult&& result) {
  if (done_[unit]) return false;
  const uint32_t p = pass_of(unit), i = uint32_t(unit - unit_begin_[p]);
  const PassSpec& spec = program_.passes[p];
  mark_done(unit);
  // (Records first: a barrier this result completes may build the artifact they feed.)
  if (spec.feeds && !result.records.empty()) builder_->add_records(*spec.feeds, unit, result.records);
  if (!tile_states_.empty()) {
    tile_states_[unit] = std::move(result.tile_state);
    // (The state it started from is spent: only each tile's latest is kept, not one per pass.)
    if (spec.tile_state) std::string().swap(tile_states_[unit_begin_[state_pass(p)] + i]);
  }
  if (spec.kind == UnitKind::Tile) films_.add_tile(p, i, std::move(result.tile));
  else films_.add_splat(p, i, std::move(result.splats));
  advance();
  return true;
}

NoiseEstimate PassSequencer::noise() const {
  // (A released film keeps its last estimate, for a finished job's status.)
  if (films_.allocated() && (!noise_ || noise_changes_ != films_.changes())) {
    noise_ = films_.noise();
    noise_changes_ = films_.changes();
  }
  return noise_ ? *noise_ : films_.noise();
}

std::optional<uint32_t> PassSequencer::first_user(uint32_t iteration) const {
  for (uint32_t p = 0; p < num_passes(); ++p)
    if (program_.passes[p].uses == iteration) return p;
  return std::nullopt;
}

void PassSequencer::build_artifact(uint32_t iteration) {
  const auto t0 = std::chrono::steady_clock::now();
  std::shared_ptr<const Artifact> made = builder_->build(iteration);
  if (artifacts_.size() <= iteration) artifacts_.resize(iteration + 1);
  for (auto& older : artifacts_) older.reset();  // (the passes that used them are complete)
  artifacts_[iteration] = std::move(made);
  if (const auto from = artifacts_[iteration]->stepped_aside_from()) films_.set_alike_from(*from);
  build_seconds_.resize(artifacts_.size());
  build_seconds_[iteration] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::optional<PassSequencer::MadeArtifact> PassSequencer::take_artifact() {
  if (handed_out_ >= artifacts_.size() || !artifacts_[handed_out_]) return std::nullopt;
  const uint32_t i = uint32_t(handed_out_++);
  return MadeArtifact{i, artifacts_[i], build_seconds_[i]};
}

void PassSequencer::artifact_stored(uint32_t i, std::string hash) {
  if (i == hashes_.size()) hashes_.push_back(std::move(hash));
  advance();
}

const Artifact* PassSequencer::artifact(uint32_t i) const {
  return i < artifacts_.size() ? artifacts_[i].get() : nullptr;
}

// A unit of the pass is done, or its adaptive counts are known: going on to it was decided
// before a restart.
bool PassSequencer::at_barrier_decided_before(uint32_t pass) const {
  return (program_.passes[pass].adaptive && plans_->decided(pass)) || pass_done_[pass] > 0;
}

// The decisions at pass p's barrier, in order; false: p stays shut (for now, or for good).
bool PassSequencer::open_barrier(uint32_t p) {
  const PassSpec& spec = program_.passes[p];
  if (complete_passes_ < p) return false;
  if (spec.may_stop && !at_barrier_decided_before(p) && films_.allocated() &&
      noise().rel_mse <= program_.target_error) {
    stopped_ = true;
    return false;
  }
  if (spec.adaptive && !plans_->decided(p)) {
    if (!films_.allocated() || films_.released()) return false;  // (released: the render has ended)
    const auto t0 = std::chrono::steady_clock::now();
    plans_->decide(p, films_.film(films_.primary_film()));
    decided_.push_back({p, plans_->latest_counts(),
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()});
  }
  if (spec.uses && first_user(*spec.uses) == p && *spec.uses >= artifacts_.size()) build_artifact(*spec.uses);
  return true;
}

// The one place passes open.
void PassSequencer::advance() {
  while (complete_passes_ < num_passes() && pass_done_[complete_passes_] == units_in(uint32_t(complete_passes_)))
    ++complete_passes_;
  while (!rebuilding_ && !stopped_ && open_passes_ < num_passes()) {
    const uint32_t p = uint32_t(open_passes_);
    const PassSpec& spec = program_.passes[p];
    if (spec.barrier && !open_barrier(p)) break;
    if (spec.uses && *spec.uses >= hashes_.size()) break;  // (its artifact is not stored yet)
    ++open_passes_;
  }
}

void PassSequencer::end_rebuild() {
  rebuilding_ = false;
  advance();
}

bool PassSequencer::restore_pass_plan(uint32_t pass, std::vector<uint32_t> counts, std::string& error) {
  if (!plans_) {
    error = "stored sample counts for a job that is not adaptive";
    return false;
  }
  return plans_->restore(pass, std::move(counts), error);
}

void PassSequencer::restore_artifacts(std::vector<std::string> hashes, std::shared_ptr<const Artifact> latest) {
  TESSERA_CHECK(!hashes.empty() && latest && builder_);
  const uint32_t last = uint32_t(hashes.size() - 1);
  builder_->restore(last, latest);
  artifacts_.assign(hashes.size(), nullptr);
  if (const auto from = latest->stepped_aside_from()) films_.set_alike_from(*from);
  artifacts_[last] = std::move(latest);
  build_seconds_.assign(hashes.size(), 0.0);
  handed_out_ = hashes.size();
  hashes_ = std::move(hashes);
}

// The unit of the tile's latest Tile pass before `next_pass` (> 0).
size_t PassSequencer::state_unit(uint32_t tile, uint32_t next_pass) const {
  const uint32_t p = program_.passes[next_pass - 1].kind == UnitKind::Tile ? next_pass - 1 : state_pass(next_pass - 1);
  return unit_begin_[p] + tile;
}

void PassSequencer::restore_tile_state(uint32_t tile, uint32_t next_pass, std::string state) {
  if (!tile_states_.empty() && next_pass > 0) tile_states_[state_unit(tile, next_pass)] = std::move(state);
}

const std::string& PassSequencer::tile_state(uint32_t tile, uint32_t next_pass) const {
  static const std::string kNone;
  return tile_states_.empty() || next_pass == 0 ? kNone : tile_states_[state_unit(tile, next_pass)];
}

void PassSequencer::release() {
  if (films_.allocated()) (void)noise();  // (kept for a finished job's status)
  films_.release();
  if (plans_) plans_->release_pixels();
  if (builder_) builder_->release();
  for (auto& a : artifacts_) a.reset();
}

}  // namespace tessera
