#include "job_state.h"

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

std::string farm_program_error(const PassProgram& program) {
  if (program.films < 1) return "a job's passes enter no film";
  return {};
}

namespace {

PassSequencer job_sequencer(const JobPlan& plan) {
  // The same sequencer `tessera render` runs with these settings (path_program.h), with the passes
  // planned at submission.
  const SequenceFrame frame{plan.window, plan.full_width, plan.full_height, plan.settings.tile_size,
                            plan.settings.sums_aovs()};
  // (A job whose passes feed point maps keeps their records, never their grids: it only stores them.)
  PassSequencer seq = plan.points ? light_vertex_sequencer(job_program(plan), frame, plan.points, PointMapUse::Store)
                                  : path_sequencer(job_program(plan), frame, plan.guide);
  if (std::string e = farm_program_error(seq.program()); !e.empty()) throw std::invalid_argument(e);
  return seq;
}

}  // namespace

JobState::JobState(uint64_t id, JobPlan plan, std::string name, int priority, double created)
    : id_(id), plan_(std::move(plan)), name_(std::move(name)), priority_(priority), created_(created),
      seq_(job_sequencer(plan_)) {
  committing_.assign(num_units(), 0);
  active_leases_.assign(num_units(), 0);
  leases_issued_.assign(num_units(), 0);
  accepted_from_.assign(num_units(), 0);
  folded_.assign(num_tiles(), 0);
  tile_committing_.assign(num_tiles(), 0);
  seq_.films().fold_later();
}

std::optional<Lease::Guide> JobState::lease_guide(size_t unit) const {
  const UnitWork w = seq_.work(unit);
  if (!w.uses) return std::nullopt;
  return Lease::Guide{seq_.artifact_hash(*w.uses), *w.uses, w.feeds.has_value()};
}

std::vector<uint32_t> JobState::passes_feeding_next() const {
  std::vector<uint32_t> out;
  const uint32_t next = seq_.artifacts_stored();
  for (uint32_t p = 0; p < num_passes(); ++p)
    if (seq_.pass(p).feeds == next) out.push_back(p);
  return out;
}

uint32_t JobState::first_pass_feeding_after(uint32_t iteration) const {
  for (uint32_t p = 0; p < num_passes(); ++p)
    if (seq_.pass(p).feeds && *seq_.pass(p).feeds > iteration) return p;
  return uint32_t(num_passes());
}

void JobState::restore_records(uint32_t pass, uint32_t tile, std::string_view records) {
  seq_.builder()->add_records(*seq_.pass(pass).feeds, unit(tile, pass), records);
}

std::optional<size_t> JobState::next_unit() const {
  if (seq_.stopped()) return std::nullopt;
  auto leasable = [&](size_t u) { return !committing_[u] && active_leases_[u] == 0 && seq_.ready(u); };
  for (auto it = returned_.begin(); it != returned_.end();) {
    if (leasable(*it)) return *it;
    it = is_done(*it) || committing_[*it] || active_leases_[*it] > 0 ? returned_.erase(it) : std::next(it);
  }
  const size_t open_end = seq_.first_unit(uint32_t(seq_.open_passes()));
  while (cursor_ < open_end && (is_done(cursor_) || committing_[cursor_] || active_leases_[cursor_] > 0)) ++cursor_;
  for (size_t u = cursor_; u < open_end; ++u)  // (past units waiting for their tile's state)
    if (leasable(u)) return u;
  return std::nullopt;
}

void JobState::lease_issued(size_t unit) {
  if (leases_issued_[unit] < UINT16_MAX) ++leases_issued_[unit];
  max_leases_per_unit_ = std::max<unsigned>(max_leases_per_unit_, leases_issued_[unit]);
}

void JobState::lease_ended(size_t unit) {
  if (active_leases_[unit] > 0) --active_leases_[unit];
  if (active_leases_[unit] == 0 && !is_done(unit) && !committing_[unit] && unit < cursor_) returned_.insert(unit);
}

void JobState::start_commit(size_t unit) {
  committing_[unit] = 1;
  if (is_tile_unit(unit)) ++tile_committing_[tile_of(unit)];
}

void JobState::commit_failed(size_t unit) {
  if (committing_[unit]) {
    committing_[unit] = 0;
    if (is_tile_unit(unit)) --tile_committing_[tile_of(unit)];
    if (unit < cursor_) returned_.insert(unit);
  }
  digests_.erase(unit);
}

void JobState::mark_done(size_t unit, uint64_t worker) {
  if (is_done(unit)) return;
  seq_.mark_done(unit);
  accepted_from_[unit] = worker;
  samples_by_worker_[worker] += unit_samples(unit);
}

bool JobState::add_unit_result(size_t unit, UnitResult&& result, uint64_t worker) {
  if (is_done(unit)) {
    ++duplicates;
    return false;
  }
  if (committing_[unit]) {
    committing_[unit] = 0;
    if (is_tile_unit(unit)) --tile_committing_[tile_of(unit)];
  }
  accepted_from_[unit] = worker;
  samples_by_worker_[worker] += unit_samples(unit);  // (before a barrier it completes decides the next pass)
  (void)seq_.add_result(unit, std::move(result));
  return true;
}

bool JobState::add_result(size_t unit, FilmTile&& tile, uint64_t worker, std::string_view training,
                          std::string tile_state) {
  UnitResult result;
  result.tile = std::move(tile);
  result.records = std::string(training);
  result.tile_state = std::move(tile_state);
  return add_unit_result(unit, std::move(result), worker);
}

bool JobState::add_splats(size_t unit, SplatSums&& splats, uint64_t worker, std::string_view records) {
  UnitResult result;
  result.splats = std::move(splats);
  result.records = std::string(records);
  return add_unit_result(unit, std::move(result), worker);
}

// The tile's region of the film (zero before the film exists) with its passes' counters.
JobState::Checkpoint JobState::film_checkpoint(uint32_t t) const {
  Checkpoint cp;
  cp.tile = t;
  cp.from = folded_[t];
  cp.passes = passes_in_film(t);
  cp.films = seq_.films().tile_regions(t);
  cp.tile_state = seq_.tile_state(t, cp.passes);
  return cp;
}

std::optional<JobState::Checkpoint> JobState::take_checkpoint(uint32_t t, uint32_t min_new) {
  if (!film_allocated() || !has_film() || passes_in_film(t) < folded_[t] + std::max<uint32_t>(1, min_new))
    return std::nullopt;
  Checkpoint cp = film_checkpoint(t);
  cp.sample_end = tile_sample_end(cp.passes);
  folded_[t] = cp.passes;
  return cp;
}

std::optional<JobState::Checkpoint> JobState::checkpoint_with(size_t u, const FilmTile& result,
                                                              const std::string& tile_state) const {
  if (!is_tile_unit(u)) return std::nullopt;  // (a Paths unit's result is stored as it came)
  const uint32_t t = tile_of(u);
  if (!has_film() || pass_of(u) != passes_in_film(t) || folded_[t] != passes_in_film(t) || tile_committing_[t] > 0)
    return std::nullopt;
  Checkpoint cp = film_checkpoint(t);
  cp.passes = passes_in_film(t) + 1;
  cp.sample_end = sample_end(u);
  // The same additions Film::add_tile makes, in the same order: the film's region once it is in.
  if (const int f = seq_.pass(pass_of(u)).film; f != kNoFilm) {
    std::vector<PixelSums>& out = cp.films[size_t(f)].mutable_pixels();
    const std::vector<PixelSums>& in = result.pixels();
    for (size_t i = 0; i < out.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        out[i].sum[c] += in[i].sum[c];
        out[i].sum_sq[c] += in[i].sum_sq[c];
      }
      out[i].count += in[i].count;
      if (cp.films[size_t(f)].has_aovs()) add_aov_sums(cp.films[size_t(f)].mutable_aovs()[i], result.aovs()[i]);
    }
  }
  cp.films[0].counters += result.counters;
  cp.tile_state = tile_state;
  return cp;
}

uint32_t JobState::tile_sample_end(uint32_t next_pass) const {
  for (uint32_t p = next_pass; p-- > 0;)
    if (seq_.pass(p).kind == UnitKind::Tile) return seq_.pass(p).sample_begin + seq_.pass(p).samples;
  return 0;
}

std::vector<uint32_t> JobState::tile_passes(uint32_t from, uint32_t to) const {
  std::vector<uint32_t> out;
  for (uint32_t p = from; p < to; ++p)
    if (seq_.pass(p).kind == UnitKind::Tile) out.push_back(p);
  return out;
}

void JobState::restore_checkpoint(uint32_t t, uint32_t passes, std::vector<FilmTile>&& films, std::string tile_state) {
  seq_.films().restore_tile(t, passes, std::move(films));
  seq_.restore_tile_state(t, passes, std::move(tile_state));
  folded_[t] = passes;
}

}  // namespace tessera::server
