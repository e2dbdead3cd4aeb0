#include "job_state.h"

#include "tessera/render/renderer.h"

#include <chrono>
#include <limits>

namespace tessera::server {

const char* phase_name(JobPhase p) {
  switch (p) {
    case JobPhase::Queued: return "queued";
    case JobPhase::Running: return "running";
    case JobPhase::Done: return "done";
    case JobPhase::Failed: return "failed";
    case JobPhase::Cancelled: return "cancelled";
  }
  return "unknown";
}

bool parse_phase(const std::string& s, JobPhase& out) {
  for (JobPhase p : {JobPhase::Queued, JobPhase::Running, JobPhase::Done, JobPhase::Failed, JobPhase::Cancelled})
    if (s == phase_name(p)) {
      out = p;
      return true;
    }
  return false;
}

JobState::JobState(uint64_t id, JobPlan plan, std::string name, int priority, double created)
    : id_(id), plan_(std::move(plan)), name_(std::move(name)), priority_(priority), created_(created) {
  // The same cuts `tessera render` makes: pass_schedule is a function of spp alone.
  tiles_ = make_tiles(plan_.window, plan_.settings.tile_size);
  passes_ = pass_schedule(uint32_t(plan_.settings.spp));
  uint32_t begin = 0;
  for (uint32_t n : passes_) {
    pass_begin_.push_back(begin);
    begin += n;
  }
  done_.assign(num_units(), 0);
  active_leases_.assign(num_units(), 0);
  accepted_from_.assign(num_units(), 0);
  next_pass_.assign(tiles_.size(), 0);
  folded_.assign(tiles_.size(), 0);
  tile_committing_.assign(tiles_.size(), 0);
  tile_counters_.assign(tiles_.size(), RenderCounters{});
  total_samples_ = uint64_t(plan_.window.area()) * uint64_t(plan_.settings.spp);
  pass_done_.assign(passes_.size(), 0);
  if (plan_.settings.adaptive)
    plans_.emplace(plan_.window, tiles_, passes_, pass_begin_, uint32_t(plan_.settings.spp));
  if (plan_.guide) guide_.emplace(*plan_.guide, passes_, uint32_t(plan_.settings.spp));
  advance_passes();
}

std::optional<Lease::Guide> JobState::lease_guide(size_t unit) const {
  const uint32_t pass = pass_of(unit);
  if (!guide_ || !guide_->guides(pass)) return std::nullopt;
  return Lease::Guide{guide_->hash(guide_->iteration_of(pass)), guide_->iteration_of(pass), guide_->trains(pass)};
}

bool JobState::check_training(size_t unit, std::string_view records, std::string& error) const {
  if (!guide_) {
    if (records.empty()) return true;
    error = "training records for a job that is not guided";
    return false;
  }
  return guide_->check_records(pass_of(unit), records, error);
}

void JobState::guide_stored(uint32_t i, std::string hash) {
  guide_->stored_as(i, std::move(hash));
  advance_passes();
}

uint32_t JobState::guide_iterations() const { return guide_ ? guide_->stored_count() : 0; }

uint64_t JobState::unit_samples(size_t unit) const {
  const uint32_t pass = pass_of(unit);
  if (plans_ && plans_->at_barrier(pass) && plans_->decided(pass)) return plans_->samples(tile_of(unit), pass);
  return uint64_t(rect(unit).area()) * (sample_end(unit) - sample_begin(unit));
}

std::optional<PassSamples> JobState::lease_samples(size_t unit) const {
  if (!plans_ || !plans_->at_barrier(pass_of(unit))) return std::nullopt;
  return plans_->tile_samples(tile_of(unit), pass_of(unit));
}

bool JobState::result_fits(size_t unit, const FilmTile& film) const {
  if (!plans_ || !plans_->at_barrier(pass_of(unit))) return true;
  return plans_->matches(tile_of(unit), pass_of(unit), film);
}

bool JobState::restore_pass_plan(uint32_t pass, std::vector<uint32_t> counts, std::string& error) {
  if (!plans_) {
    error = "stored sample counts for a job that is not adaptive";
    return false;
  }
  return plans_->restore(pass, std::move(counts), error);
}

Image JobState::image() const {
  if (film_) return film_->to_image();
  return Image(plan_.window.width(), plan_.window.height(), 3);
}

void JobState::aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const {
  if (film_ && (film_->has_aovs() || layer == AovLayer::Variance)) film_->aov_rows(layer, img, row_begin, row_end);
}

void JobState::image_rows(Image& img, int row_begin, int row_end) const {
  if (film_) film_->to_image_rows(img, row_begin, row_end);  // (else black, as allocated)
}

NoiseEstimate JobState::noise() const {
  if (!film_) return noise_ ? *noise_ : NoiseEstimate{std::numeric_limits<double>::infinity(), 0};
  if (!noise_ || noise_units_ != done_units_) {
    noise_ = estimate_noise(*film_);
    noise_units_ = done_units_;
  }
  return *noise_;
}

// A unit of the pass is done, or its adaptive counts are known: going on to it was decided
// before a restart.
bool JobState::pass_decided_before(uint32_t pass) const {
  if (plans_ && plans_->at_barrier(pass) && plans_->decided(pass)) return true;
  for (size_t t = 0; t < tiles_.size(); ++t)
    if (is_done(unit(uint32_t(t), pass))) return true;
  return false;
}

bool JobState::at_barrier(uint32_t pass) const {
  return (plan_.settings.target_error > 0 && pass >= 1) || (plans_ && plans_->at_barrier(pass)) ||
         (guide_ && guide_->at_barrier(pass));
}

// The one place passes open. A barrier (target error, an adaptive pass, a guide made from the
// pass before) is passed only once every tile has every pass before it, when the film holds
// exactly those passes; a guided pass opens once the tree it renders with is stored.
void JobState::advance_passes() {
  while (complete_passes_ < passes_.size() && pass_done_[complete_passes_] == tiles_.size()) ++complete_passes_;
  while (!rebuilding_ && !converged_ && open_passes_ < passes_.size()) {
    const uint32_t p = uint32_t(open_passes_);
    if (at_barrier(p)) {
      if (complete_passes_ < p) break;
      if (plan_.settings.target_error > 0 && !pass_decided_before(p) && film_ &&
          noise().rel_mse <= plan_.settings.target_error) {
        converged_ = true;
        break;
      }
      if (plans_ && plans_->at_barrier(p) && !plans_->decided(p)) {
        if (!film_) break;  // (released: the job has ended)
        const auto t0 = std::chrono::steady_clock::now();
        plans_->decide(p, *film_);
        new_plans_.push_back({p, plans_->latest_counts(),
                              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()});
      }
      if (guide_ && guide_->at_barrier(p) && !guide_->made(p)) guide_->end_iteration();
    }
    if (guide_ && guide_->guides(p) && !guide_->stored(guide_->iteration_of(p))) break;
    ++open_passes_;
  }
}

std::optional<size_t> JobState::next_unit() const {
  if (converged_) return std::nullopt;
  const size_t open_end = open_passes_ * tiles_.size();
  for (size_t u = first_open_; u < open_end; ++u)
    if (done_[u] == kOpen && active_leases_[u] == 0) return u;
  return std::nullopt;
}

void JobState::lease_ended(size_t unit) {
  if (active_leases_[unit] > 0) --active_leases_[unit];
}

void JobState::mark_done(size_t unit, uint64_t worker) {
  if (done_[unit] == kDone) return;
  done_[unit] = kDone;
  accepted_from_[unit] = worker;
  ++done_units_;
  ++pass_done_[pass_of(unit)];
  done_samples_ += unit_samples(unit);
  samples_by_worker_[worker] += unit_samples(unit);
  while (first_open_ < done_.size() && done_[first_open_] == kDone) ++first_open_;
  while (complete_passes_ < passes_.size() && pass_done_[complete_passes_] == tiles_.size()) ++complete_passes_;
}

bool JobState::add_result(size_t unit, FilmTile&& tile, uint64_t worker, std::string_view training) {
  if (done_[unit] == kDone) {
    ++duplicates;
    return false;
  }
  if (done_[unit] == kCommitting) --tile_committing_[tile_of(unit)];
  mark_done(unit, worker);
  counters_ += tile.counters;
  if (!training.empty()) guide_->add_records(training);  // (before a barrier may end the iteration)

  // Passes of a tile enter the film in pass order; a later pass waits for the earlier ones.
  const uint32_t t = tile_of(unit);
  allocate_film();
  waiting_.emplace(unit, std::move(tile));
  for (auto it = waiting_.find(this->unit(t, next_pass_[t])); it != waiting_.end();
       it = waiting_.find(this->unit(t, next_pass_[t]))) {
    if (film_ && in_film(pass_of(it->first))) film_->add_tile(it->second);
    ++film_changes_;
    tile_counters_[t] += it->second.counters;
    waiting_.erase(it);
    if (++next_pass_[t] == passes_.size()) break;
  }
  advance_passes();
  return true;
}

// The tile's region of the film (zero before the film exists) with its passes' counters.
JobState::Checkpoint JobState::film_checkpoint(uint32_t t) const {
  Checkpoint cp;
  cp.tile = t;
  cp.from = folded_[t];
  cp.passes = next_pass_[t];
  const TileRect& r = tiles_[t];
  cp.sums.reset(r, plan_.settings.denoise);
  if (film_) {
    std::vector<PixelSums>& out = cp.sums.mutable_pixels();
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const size_t i = size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0);
        out[i] = film_->pixel({x, y});
        if (cp.sums.has_aovs()) cp.sums.mutable_aovs()[i] = film_->aov({x, y});
      }
  }
  cp.sums.counters = tile_counters_[t];
  return cp;
}

std::optional<JobState::Checkpoint> JobState::take_checkpoint(uint32_t t, uint32_t min_new) {
  if (!film_ || next_pass_[t] < folded_[t] + std::max<uint32_t>(1, min_new)) return std::nullopt;
  Checkpoint cp = film_checkpoint(t);
  cp.sample_end = sample_end(unit(t, cp.passes - 1));
  folded_[t] = cp.passes;
  return cp;
}

std::optional<JobState::Checkpoint> JobState::checkpoint_with(size_t u, const FilmTile& result) const {
  const uint32_t t = tile_of(u);
  if (film_released_ || pass_of(u) != next_pass_[t] || folded_[t] != next_pass_[t] || tile_committing_[t] > 0)
    return std::nullopt;
  Checkpoint cp = film_checkpoint(t);
  cp.passes = next_pass_[t] + 1;
  cp.sample_end = sample_end(u);
  // The same additions add_tile makes, in the same order: the film's region once it is in.
  std::vector<PixelSums>& out = cp.sums.mutable_pixels();
  const std::vector<PixelSums>& in = result.pixels();
  for (size_t i = 0; i < out.size() && in_film(pass_of(u)); ++i) {
    for (int c = 0; c < 3; ++c) {
      out[i].sum[c] += in[i].sum[c];
      out[i].sum_sq[c] += in[i].sum_sq[c];
    }
    out[i].count += in[i].count;
    if (cp.sums.has_aovs()) add_aov_sums(cp.sums.mutable_aovs()[i], result.aovs()[i]);
  }
  cp.sums.counters += result.counters;
  return cp;
}

void JobState::allocate_film() {
  if (!film_ && !film_released_)
    film_ = std::make_unique<Film>(plan_.window, plan_.full_width, plan_.full_height, plan_.settings.denoise);
}

void JobState::restore_checkpoint(uint32_t t, uint32_t passes, FilmTile&& sums) {
  allocate_film();
  if (film_) film_->add_tile(sums);
  ++film_changes_;
  counters_ += sums.counters;
  tile_counters_[t] = sums.counters;
  next_pass_[t] = folded_[t] = passes;
}

}  // namespace tessera::server
