#include "tessera/sequence/photon_program.h"

#include "tessera/core/check.h"
#include "tessera/render/render_tile.h"
#include "tessera/sequence/path_program.h"

#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace tessera {

namespace {

bool finite3(const float v[3]) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }
bool non_negative3(const float v[3]) { return v[0] >= 0.f && v[1] >= 0.f && v[2] >= 0.f; }

bool valid(const Photon& ph) { return finite3(ph.p) && finite3(ph.power) && non_negative3(ph.power) && ph.length >= 1; }
bool valid(const LightVertexRecord& v) {
  return finite3(v.p) && finite3(v.beta) && non_negative3(v.beta) && v.length >= 1 && std::isfinite(v.d_vcm) &&
         std::isfinite(v.d_vm) && v.d_vcm >= 0.f && v.d_vm >= 0.f;
}

// Whether untrusted bytes are whole valid records, at most the cap with `held` bytes already in.
template <typename R>
bool check_records_of(std::string_view bytes, uint64_t held, std::string& error) {
  if (bytes.size() % sizeof(R) != 0) {
    error = "records: " + std::to_string(bytes.size()) + " bytes is not a whole number of " +
            std::to_string(sizeof(R)) + "-byte records";
    return false;
  }
  if (held + bytes.size() > kMaxPhotonMapBytes) {
    error = "records: a pass's points exceed the cap of " + std::to_string(kMaxPhotonMapBytes) + " bytes";
    return false;
  }
  return true;
}

template <typename R>
bool check_values(std::string_view bytes, std::string& error) {
  for (size_t i = 0; i < bytes.size() / sizeof(R); ++i) {
    R r;
    std::memcpy(static_cast<void*>(&r), bytes.data() + i * sizeof(R), sizeof(R));
    if (!valid(r)) {
      error = "records: record " + std::to_string(i) + " is not finite or out of range";
      return false;
    }
  }
  return true;
}

// Records from untrusted bytes: whole records, each valid, at most the cap.
template <typename R>
bool read_records(std::string_view bytes, std::vector<R>& out, std::string& error) {
  if (!check_records_of<R>(bytes, out.size() * sizeof(R), error) || !check_values<R>(bytes, error)) return false;
  const size_t first = out.size();
  out.resize(first + bytes.size() / sizeof(R));
  if (!bytes.empty()) std::memcpy(static_cast<void*>(out.data() + first), bytes.data(), bytes.size());
  return true;
}

// The artifact's bytes: zstd of the radius and the records.
std::string encode_points(float radius, const std::vector<std::string_view>& parts) {
  size_t size = sizeof radius;
  for (std::string_view p : parts) size += p.size();
  std::string raw;
  raw.reserve(size);
  raw.append(reinterpret_cast<const char*>(&radius), sizeof radius);
  for (std::string_view p : parts) raw.append(p);
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 1);
  out.resize(ZSTD_isError(n) ? 0 : n);  // (compressBound makes an error impossible)
  return out;
}

// A pass of `paths` in about 16 units (so that every thread of a machine has some), from 1,024 to
// 65,536 paths each. The units' records join in unit order, so the split changes no photon map.
uint64_t paths_per_unit_for(uint64_t paths) { return std::clamp<uint64_t>((paths + 15) / 16, 1024, uint64_t(1) << 16); }

PassSpec pass(UnitKind kind, uint32_t k, uint32_t samples) {
  PassSpec p;
  p.kind = kind;
  p.sample_begin = k;
  p.samples = samples;
  return p;
}

// Iteration k of a program of point maps: `paths` feeds map k, then `tile`, a barrier, renders
// with it.
void add_map_iteration(PassProgram& program, uint32_t k, PassSpec paths, PassSpec tile) {
  paths.feeds = k;
  tile.barrier = true;
  tile.uses = k;
  program.passes.push_back(paths);
  program.passes.push_back(tile);
}

}  // namespace

uint32_t sppm_passes(const IntegratorSettings& settings, uint32_t spp) {
  return settings.max_passes >= 0 ? std::min(spp, uint32_t(settings.max_passes)) : spp;
}

PassProgram photon_program(uint32_t passes, uint64_t photons) {
  TESSERA_CHECK(photons > 0 && photons <= kMaxPhotonsPerPass);
  PassProgram program;
  program.spp = passes;
  program.paths_per_unit = paths_per_unit_for(photons);
  for (uint32_t k = 0; k < passes; ++k) {
    PassSpec trace = pass(UnitKind::Paths, k, 0);
    trace.photons = photons;
    trace.film = kNoFilm;
    PassSpec gather = pass(UnitKind::Tile, k, 1);
    gather.tile_state = k > 0;
    add_map_iteration(program, k, trace, gather);
  }
  return program;
}

PassProgram vcm_program(uint32_t spp, uint64_t window_pixels) {
  PassProgram program;
  program.spp = spp;
  program.paths_per_unit = paths_per_unit_for(window_pixels);
  for (uint32_t k = 0; k < spp; ++k) {
    PassSpec light = pass(UnitKind::Paths, k, 1);
    light.same_samples = true;
    add_map_iteration(program, k, light, pass(UnitKind::Tile, k, 1));
  }
  return program;
}

float PointMapPlan::radius(uint32_t iteration) const {
  return type == IntegratorType::Sppm ? initial_radius : vcm_radius(initial_radius, alpha, iteration);
}

std::optional<PointMapPlan> point_map_plan(const Scene& scene) {
  const IntegratorSettings& s = scene.integrator;
  if (s.type == IntegratorType::Sppm) return PointMapPlan{s.type, sppm_initial_radius(scene), s.alpha};
  if (s.type == IntegratorType::Vcm && s.merge) return PointMapPlan{s.type, vcm_initial_radius(scene), s.alpha};
  return std::nullopt;
}

PassProgram light_vertex_program(const Scene& scene, uint32_t spp, uint64_t window_pixels) {
  const IntegratorSettings& s = scene.integrator;
  if (s.type == IntegratorType::Sppm) return photon_program(sppm_passes(s, spp), s.photon_count);
  TESSERA_CHECK(s.type == IntegratorType::Vcm);
  if (s.merge) return vcm_program(spp, window_pixels);
  return path_program(PathProgramOptions{spp, 0, false, {}, std::nullopt, traces_light_paths(s)});
}

template <typename R>
std::string GridArtifact<R>::encode() const {
  return encode_points(grid_.max_radius(), {std::string_view(reinterpret_cast<const char*>(grid_.records().data()),
                                                             grid_.records().size() * sizeof(R))});
}

std::string PointRecordsArtifact::encode() const {
  return encode_points(radius_, std::vector<std::string_view>(records_.begin(), records_.end()));
}

size_t PointRecordsArtifact::memory_bytes() const {
  size_t n = 0;
  for (const std::string& r : records_) n += r.size();
  return n;
}

template <typename R>
std::shared_ptr<const Artifact> GridBuilder<R>::build(uint32_t iteration) {
  TESSERA_CHECK(iteration == next_);
  ++next_;
  const float radius = radius_(iteration);
  std::map<uint64_t, std::string> records = std::move(records_);
  records_.clear();
  bytes_ = 0;
  if (use_ == PointMapUse::Store) {
    std::vector<std::string> parts;
    parts.reserve(records.size());
    for (auto& [unit, bytes] : records) parts.push_back(std::move(bytes));
    return std::make_shared<const PointRecordsArtifact>(radius, std::move(parts));
  }
  size_t total = 0;
  for (const auto& [unit, bytes] : records) total += bytes.size() / sizeof(R);
  std::vector<R> points;
  points.reserve(total);
  std::string error;
  for (const auto& [unit, bytes] : records) TESSERA_CHECK(read_records(bytes, points, error));  // (our own)
  return std::make_shared<const GridArtifact<R>>(PointGrid<R>(std::move(points), radius));
}

template <typename R>
bool GridBuilder<R>::check_records(uint32_t iteration, std::string_view records, std::string& error) const {
  if (iteration != next_) {
    error = "records for pass " + std::to_string(iteration) + " while pass " + std::to_string(next_) + " is fed";
    return false;
  }
  return check_records_of<R>(records, bytes_, error);
}

template <typename R>
void GridBuilder<R>::add_records(uint32_t iteration, uint64_t unit, std::string_view records) {
  TESSERA_CHECK(iteration == next_);
  std::string& held = records_[unit];
  bytes_ = bytes_ - held.size() + records.size();
  held = std::string(records);
}

template <typename R>
std::shared_ptr<const Artifact> GridBuilder<R>::decode(std::string_view bytes, std::string& error) const {
  const unsigned long long size = ZSTD_getFrameContentSize(bytes.data(), bytes.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size < sizeof(float) ||
      size > kMaxPhotonMapBytes + sizeof(float)) {
    error = "point map: not a zstd frame of a known size up to the cap of " + std::to_string(kMaxPhotonMapBytes) + " bytes";
    return nullptr;
  }
  std::string raw(size_t(size), '\0');
  const size_t n = ZSTD_decompress(raw.data(), raw.size(), bytes.data(), bytes.size());
  float radius = 0.f;
  if (!ZSTD_isError(n) && n == raw.size()) std::memcpy(&radius, raw.data(), sizeof radius);
  if (!(radius > 0.f) || !std::isfinite(radius)) {
    error = "point map: corrupt or truncated";
    return nullptr;
  }
  const std::string_view records = std::string_view(raw).substr(sizeof radius);
  if (use_ == PointMapUse::Store) {
    if (!check_records_of<R>(records, 0, error) || !check_values<R>(records, error)) return nullptr;
    return std::make_shared<const PointRecordsArtifact>(radius, std::vector<std::string>{std::string(records)});
  }
  std::vector<R> points;
  if (!read_records(records, points, error)) return nullptr;
  return std::make_shared<const GridArtifact<R>>(PointGrid<R>(std::move(points), radius));
}

template <typename R>
void GridBuilder<R>::restore(uint32_t iteration, std::shared_ptr<const Artifact> /*artifact*/) {
  records_.clear();
  bytes_ = 0;
  next_ = iteration + 1;
}

template class GridArtifact<Photon>;
template class GridArtifact<LightVertexRecord>;
template class GridBuilder<Photon>;
template class GridBuilder<LightVertexRecord>;

bool check_point_records(IntegratorType type, std::string_view records, std::string& error) {
  if (type == IntegratorType::Sppm) return check_records_of<Photon>(records, 0, error) && check_values<Photon>(records, error);
  return check_records_of<LightVertexRecord>(records, 0, error) && check_values<LightVertexRecord>(records, error);
}

std::shared_ptr<const Artifact> decode_point_map(IntegratorType type, std::string_view bytes, std::string& error) {
  auto no_radius = [](uint32_t) { return 0.f; };  // (decoding takes the stored one)
  if (type == IntegratorType::Sppm) return GridBuilder<Photon>(no_radius).decode(bytes, error);
  return GridBuilder<LightVertexRecord>(no_radius).decode(bytes, error);
}

bool check_sppm_state(std::string_view state, size_t pixels, std::string& error) {
  if (state.size() != pixels * sizeof(SppmPixel)) {
    error = "per-pixel state of " + std::to_string(state.size()) + " bytes, not " + std::to_string(pixels) + " pixels of " +
            std::to_string(sizeof(SppmPixel));
    return false;
  }
  for (size_t i = 0; i < pixels; ++i) {
    SppmPixel px;
    std::memcpy(static_cast<void*>(&px), state.data() + i * sizeof px, sizeof px);
    const bool ok = std::isfinite(px.radius) && px.radius >= 0.f && std::isfinite(px.n) && px.n >= 0.f &&
                    std::isfinite(px.tau[0]) && std::isfinite(px.tau[1]) && std::isfinite(px.tau[2]) &&
                    px.tau[0] >= 0 && px.tau[1] >= 0 && px.tau[2] >= 0;
    if (!ok) {
      error = "per-pixel state: pixel " + std::to_string(i) + " is not finite or out of range";
      return false;
    }
  }
  return true;
}

PassSequencer light_vertex_sequencer(const Scene& scene, uint32_t spp, const SequenceFrame& frame) {
  return light_vertex_sequencer(light_vertex_program(scene, spp, uint64_t(frame.window.area())), frame,
                                point_map_plan(scene), PointMapUse::Render);
}

PassSequencer light_vertex_sequencer(PassProgram program, const SequenceFrame& frame,
                                     const std::optional<PointMapPlan>& plan, PointMapUse use) {
  if (!plan) return path_sequencer(std::move(program), frame, std::nullopt);
  auto radius = [p = *plan](uint32_t k) { return p.radius(k); };
  if (plan->type == IntegratorType::Sppm)
    return PassSequencer(std::move(program), frame, std::make_unique<GridBuilder<Photon>>(radius, use));
  return PassSequencer(std::move(program), frame, std::make_unique<GridBuilder<LightVertexRecord>>(radius, use));
}

namespace {

void render_gather(const Scene& scene, const PhotonMap& map, const UnitWork& work, uint32_t seed, UnitResult& result) {
  std::vector<SppmPixel> state(size_t(work.rect.area()));
  if (work.tile_state) {
    TESSERA_CHECK(work.tile_state->size() == state.size() * sizeof(SppmPixel));
    std::memcpy(static_cast<void*>(state.data()), work.tile_state->data(), work.tile_state->size());
  }
  sppm_gather(scene, map, work.rect, work.sample_begin, seed, state, result.tile);
  result.tile_state.assign(reinterpret_cast<const char*>(state.data()), state.size() * sizeof(SppmPixel));
}

// Iteration k's merging (none when merging is off: then it is bdpt's).
VcmIteration vcm_iteration(const Scene& scene, const LightVertexMap* map, uint32_t k) {
  if (!scene.integrator.merge) return {};
  return {map, vcm_radius(scene, k), double(film_window(scene.film).area())};
}

}  // namespace

void render_light_vertex_unit(const Scene& scene, const Artifact* artifact, const UnitWork& work, uint32_t seed,
                              UnitResult& result) {
  const bool sppm = scene.integrator.type == IntegratorType::Sppm;
  const TileRect window = film_window(scene.film);
  result.records.clear();
  result.tile_state.clear();
  if (work.kind == UnitKind::Paths && sppm) {
    thread_local std::vector<Photon> photons;
    photons.clear();
    result.splats.reset(window);
    trace_photons(scene, work.sample_begin, work.path_begin, work.path_end, seed, photons, result.splats.counters);
    result.records = grid_records(photons);
  } else if (work.kind == UnitKind::Paths) {
    thread_local LightSplats splats;
    thread_local std::vector<LightVertexRecord> records;
    splats.reset(window, scene.film.width, scene.film.height);
    records.clear();
    trace_vcm_light_paths(scene, vcm_iteration(scene, nullptr, work.sample_begin), work.path_begin, work.path_end,
                          seed, splats, records);
    to_splat_sums(splats, result.splats);
    if (work.feeds) result.records = grid_records(records);
  } else if (sppm) {
    TESSERA_CHECK(artifact != nullptr);
    render_gather(scene, static_cast<const PhotonMapArtifact*>(artifact)->grid(), work, seed, result);
  } else {
    const auto* map = artifact ? &static_cast<const LightVertexArtifact*>(artifact)->grid() : nullptr;
    const VcmIteration it = vcm_iteration(scene, map, work.sample_begin);
    const auto integrator = make_vcm_integrator(scene.integrator, it);
    const PassSamples samples = PassSamples::uniform(work.rect, work.sample_begin, work.sample_end);
    render_tile(scene, *integrator, work.rect, samples, seed, result.tile, nullptr, false);
  }
}

}  // namespace tessera
