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

// Records from untrusted bytes: whole records, each valid, at most the cap.
template <typename R>
bool read_records(std::string_view bytes, std::vector<R>& out, std::string& error) {
  if (bytes.size() % sizeof(R) != 0) {
    error = "records: " + std::to_string(bytes.size()) + " bytes is not a whole number of " +
            std::to_string(sizeof(R)) + "-byte records";
    return false;
  }
  if (out.size() * sizeof(R) + bytes.size() > kMaxPhotonMapBytes) {
    error = "records: a pass's points exceed the cap of " + std::to_string(kMaxPhotonMapBytes) + " bytes";
    return false;
  }
  const size_t first = out.size();
  out.resize(first + bytes.size() / sizeof(R));
  if (!bytes.empty()) std::memcpy(static_cast<void*>(out.data() + first), bytes.data(), bytes.size());
  for (size_t i = first; i < out.size(); ++i)
    if (!valid(out[i])) {
      error = "records: record " + std::to_string(i - first) + " is not finite or out of range";
      out.resize(first);
      return false;
    }
  return true;
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
    trace.feeds = k;
    PassSpec gather = pass(UnitKind::Tile, k, 1);
    gather.barrier = true;
    gather.uses = k;
    gather.tile_state = k > 0;
    program.passes.push_back(trace);
    program.passes.push_back(gather);
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
    light.feeds = k;
    PassSpec camera = pass(UnitKind::Tile, k, 1);
    camera.barrier = true;
    camera.uses = k;
    program.passes.push_back(light);
    program.passes.push_back(camera);
  }
  return program;
}

template <typename R>
std::string GridArtifact<R>::encode() const {
  const float radius = grid_.max_radius();
  std::string raw(reinterpret_cast<const char*>(&radius), sizeof radius);
  raw += grid_records(grid_.records());
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 1);
  out.resize(ZSTD_isError(n) ? 0 : n);  // (compressBound makes an error impossible)
  return out;
}

template <typename R>
std::shared_ptr<const Artifact> GridBuilder<R>::build(uint32_t iteration) {
  TESSERA_CHECK(iteration == next_);
  std::vector<R> points;
  size_t total = 0;
  for (const auto& [unit, bytes] : records_) total += bytes.size() / sizeof(R);
  points.reserve(total);
  std::string error;
  for (const auto& [unit, bytes] : records_) TESSERA_CHECK(read_records(bytes, points, error));  // (checked on arrival)
  records_.clear();
  ++next_;
  return std::make_shared<const GridArtifact<R>>(PointGrid<R>(std::move(points), radius_(iteration)));
}

template <typename R>
bool GridBuilder<R>::check_records(uint32_t iteration, std::string_view records, std::string& error) const {
  if (iteration != next_) {
    error = "records for pass " + std::to_string(iteration) + " while pass " + std::to_string(next_) + " is fed";
    return false;
  }
  std::vector<R> points;
  return read_records(records, points, error);
}

template <typename R>
void GridBuilder<R>::add_records(uint32_t iteration, uint64_t unit, std::string_view records) {
  TESSERA_CHECK(iteration == next_);
  records_[unit] = std::string(records);
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
  std::vector<R> points;
  if (!read_records(std::string_view(raw).substr(sizeof radius), points, error)) return nullptr;
  return std::make_shared<const GridArtifact<R>>(PointGrid<R>(std::move(points), radius));
}

template <typename R>
void GridBuilder<R>::restore(uint32_t iteration, std::shared_ptr<const Artifact> /*artifact*/) {
  records_.clear();
  next_ = iteration + 1;
}

template class GridArtifact<Photon>;
template class GridArtifact<LightVertexRecord>;
template class GridBuilder<Photon>;
template class GridBuilder<LightVertexRecord>;

PassSequencer light_vertex_sequencer(const Scene& scene, uint32_t spp, const SequenceFrame& frame) {
  const IntegratorSettings& s = scene.integrator;
  if (s.type == IntegratorType::Sppm) {
    const float r0 = sppm_initial_radius(scene);
    return PassSequencer(photon_program(sppm_passes(s, spp), s.photon_count), frame,
                         std::make_unique<GridBuilder<Photon>>([r0](uint32_t) { return r0; }));
  }
  TESSERA_CHECK(s.type == IntegratorType::Vcm);
  if (!s.merge) return path_sequencer(PathProgramOptions{spp, 0, false, {}, std::nullopt, traces_light_paths(s)}, frame);
  const Scene* sc = &scene;
  return PassSequencer(vcm_program(spp, uint64_t(frame.window.area())), frame,
                       std::make_unique<GridBuilder<LightVertexRecord>>([sc](uint32_t k) { return vcm_radius(*sc, k); }));
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
