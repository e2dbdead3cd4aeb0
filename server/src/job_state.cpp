#include "job_state.h"

#include "tessera/render/renderer.h"

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
    : id_(id), plan_(std::move(plan)), name_(std::move(name)), priority_(priority), created_(created),
      film_(std::make_unique<Film>(plan_.window, plan_.full_width, plan_.full_height)) {
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
  next_pass_.assign(tiles_.size(), 0);
  total_samples_ = uint64_t(plan_.window.area()) * uint64_t(plan_.settings.spp);
}

std::optional<size_t> JobState::next_unit() const {
  for (size_t u = first_open_; u < done_.size(); ++u)
    if (!done_[u] && active_leases_[u] == 0) return u;
  return std::nullopt;
}

void JobState::lease_ended(size_t unit) {
  if (active_leases_[unit] > 0) --active_leases_[unit];
}

void JobState::mark_done(size_t unit, uint64_t worker) {
  if (done_[unit]) return;
  done_[unit] = 1;
  ++done_units_;
  done_samples_ += unit_samples(unit);
  samples_by_worker_[worker] += unit_samples(unit);
  while (first_open_ < done_.size() && done_[first_open_]) ++first_open_;
}

bool JobState::add_result(size_t unit, FilmTile&& tile, uint64_t worker) {
  if (done_[unit]) {
    ++duplicates;
    return false;
  }
  mark_done(unit, worker);
  counters_ += tile.counters;

  // Passes of a tile enter the film in pass order; a later pass waits for the earlier ones.
  const uint32_t t = tile_of(unit);
  waiting_.emplace(unit, std::move(tile));
  for (auto it = waiting_.find(this->unit(t, next_pass_[t])); it != waiting_.end();
       it = waiting_.find(this->unit(t, next_pass_[t]))) {
    if (film_) film_->add_tile(it->second);
    waiting_.erase(it);
    if (++next_pass_[t] == passes_.size()) break;
  }
  return true;
}

}  // namespace tessera::server
