// A job from its stored state: its row, its decisions (adaptive counts, artifacts and the records
// that feed the next), its checkpoints and its results, in that order, so that the film's sums are
// what they were before a restart, bit for bit.
#include "coordinator_impl.h"

#include "tessera/farm/sample_counts.h"
#include "tessera/farm/sha256.h"
#include "tessera/farm/tile_result.h"

namespace tessera::server {

std::unique_ptr<JobState> Coordinator::Impl::job_from_row(const JobRow& row) const {
  JobPlan plan;
  std::string error;
  if (!job_plan_from_json(nlohmann::json::parse(row.plan_json), plan, error))
    throw std::runtime_error("job " + std::to_string(row.id) + " in the state database: " + error);
  auto job = std::make_unique<JobState>(row.id, std::move(plan), row.name, row.priority, row.created);
  JobPhase phase;
  job->restore_phase(parse_phase(row.state, phase) ? phase : JobPhase::Failed);
  job->error = row.error;
  job->started = row.started;
  job->finished = row.finished;
  return job;
}

void Coordinator::Impl::restore_artifacts(JobState& job) {
  std::vector<std::string> hashes = store.guides(job.id());
  if (hashes.empty()) return;  // (not even its first artifact was stored: it is made again)
  std::string bytes, error;
  try {
    bytes = read_file(guide_path(hashes.back()));
  } catch (const std::exception& e) {
    error = e.what();
  }
  std::shared_ptr<const Artifact> latest;
  if (sha256_hex(bytes) == hashes.back()) latest = job.sequencer().builder()->decode(bytes, error);
  if (!latest)
    throw std::runtime_error("job " + std::to_string(job.id()) + ": its stored guide " + hashes.back() +
                             " is missing or corrupt " + error);
  job.restore_artifacts(std::move(hashes), std::move(latest));
  for (uint32_t pass : job.passes_feeding_next())
    store.for_each_training(job.id(), pass,
                            [&](uint32_t tile, std::string&& records) { job.restore_records(pass, tile, records); });
}

std::unique_ptr<JobState> Coordinator::Impl::rebuild_job(const JobRow& row) {
  auto job = job_from_row(row);
  const std::string where = "job " + std::to_string(row.id) + ": ";
  job->begin_rebuild();
  if (job->sequencer().builder()) restore_artifacts(*job);
  // An adaptive job's decided passes first: its results are checked against them.
  store.for_each_pass_plan(row.id, [&](uint32_t pass, std::string&& data) {
    std::vector<uint32_t> counts;
    std::string err;
    if (!decode_sample_counts(data, size_t(job->plan().window.area()), counts, err) ||
        !job->restore_pass_plan(pass, std::move(counts), err))
      throw std::runtime_error(where + err);
  });
  // Each tile's checkpoint first, then the passes after it, in pass order: the film's sums as they were.
  store.for_each_checkpoint(row.id, [&](CheckpointRow&& c) {
    std::vector<TileResult> films;
    std::string err;
    if (!decode_checkpoint(c.data, films, err)) throw std::runtime_error(where + "stored checkpoint is corrupt: " + err);
    bool fits = c.tile < job->num_tiles() && c.passes > 0 && c.passes <= job->num_passes() &&
                films.size() == size_t(job->sequencer().program().films) &&
                films[0].sample_end == job->tile_sample_end(c.passes);
    for (const TileResult& f : films)
      fits = fits && f.film.rect() == job->sequencer().tiles()[c.tile] && f.film.has_aovs() == job->plan().settings.sums_aovs();
    if (!fits) throw std::runtime_error(where + "stored checkpoint of tile " + std::to_string(c.tile) + " does not fit the job");
    std::vector<FilmTile> sums;
    for (TileResult& f : films) sums.push_back(std::move(f.film));
    job->restore_checkpoint(c.tile, c.passes, std::move(sums), std::move(films[0].tile_state));
  });
  store.for_each_result(row.id, [&](ResultRow&& r) {
    if (!job->has_unit(r.tile, r.pass)) return;
    const size_t unit = job->unit(r.tile, r.pass);
    if (!job->pass_decided(r.pass))
      throw std::runtime_error(where + "a result of pass " + std::to_string(r.pass) + " without its stored sample counts");
    if (r.data.empty() || (job->is_tile_unit(unit) && r.pass < job->passes_in_film(r.tile)))
      return job->mark_done(unit, r.worker);  // (held by its tile's checkpoint)
    Result<UnitUpload> stored = decode_upload(r.data, int64_t(1) << 30);
    if (!stored.ok()) throw std::runtime_error(where + "stored result is corrupt: " + stored.status.detail);
    const UnitUpload& u = stored.value;
    if (job->is_tile_unit(unit) != bool(u.tile) || (u.tile && u.tile->film.has_aovs() != job->plan().settings.sums_aovs()))
      throw std::runtime_error(where + "a stored result of pass " + std::to_string(r.pass) + " does not fit the job");
    (void)(u.tile ? job->add_result(unit, std::move(u.tile->film), r.worker, {}, std::move(u.tile->tile_state))
                  : job->add_splats(unit, std::move(u.splats->splats), r.worker));
  });
  job->end_rebuild();
  return job;
}

namespace {

// A checkpoint of a job with several films: the magic, the count, and each film's sums encoded as a
// tile result, its length first (8 bytes each, little-endian). One film's is that tile result alone.
constexpr std::string_view kFilmsMagic = "TSFILMS1";

void put_u64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(char((v >> (8 * i)) & 0xff));
}

uint64_t get_u64(std::string_view& in) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(in[size_t(i)])) << (8 * i);
  in.remove_prefix(8);
  return v;
}

}  // namespace

std::string encode_checkpoint(uint64_t job, const JobState::Checkpoint& cp) {
  std::vector<std::string> parts;
  for (size_t f = 0; f < cp.films.size(); ++f) {
    TileResult sums;
    sums.job_id = job;
    sums.tile = cp.tile;
    sums.pass = cp.passes - 1;
    sums.sample_end = cp.sample_end;
    sums.film = cp.films[f];
    if (f == 0) sums.tile_state = cp.tile_state;
    // Uncompressed: a checkpoint is written for most results, by the group commit's one writer, and
    // compressing (even zstd's fastest mode) took a third of that writer's time to save a fifth of
    // the bytes (sums are noise in their low bits). One per tile is within the storage bound as is.
    parts.push_back(encode_tile_result(sums, kUncompressed));
  }
  if (parts.size() == 1) return std::move(parts[0]);
  std::string out(kFilmsMagic);
  put_u64(out, parts.size());
  for (const std::string& p : parts) put_u64(out, p.size()), out += p;
  return out;
}

bool decode_checkpoint(std::string_view bytes, std::vector<TileResult>& films, std::string& error) {
  films.clear();
  if (!bytes.starts_with(kFilmsMagic)) return decode_tile_result(bytes, films.emplace_back(), error);
  bytes.remove_prefix(kFilmsMagic.size());
  if (bytes.size() < 8) return error = "truncated", false;
  const uint64_t count = get_u64(bytes);
  for (uint64_t f = 0; f < count; ++f) {
    if (bytes.size() < 8) return error = "truncated", false;
    const uint64_t n = get_u64(bytes);
    if (n > bytes.size() || !decode_tile_result(bytes.substr(0, n), films.emplace_back(), error))
      return error = "film " + std::to_string(f) + ": " + (error.empty() ? "truncated" : error), false;
    bytes.remove_prefix(n);
  }
  if (count == 0 || !bytes.empty()) return error = "film count or length", false;
  return true;
}

}  // namespace tessera::server
