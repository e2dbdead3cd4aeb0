// The passes of the integrators that refine their estimate from the light of their own pass:
// sppm's photons and vcm's light vertices (render/sppm.h, render/vcm.h).
//
// sppm, per pass k: a photon pass (Paths units of photon index ranges, whose records are their
// photons) that feeds artifact iteration k, the pass's photon map; then a gather pass (Tile units,
// a barrier) that renders with it, starting from the per-pixel state its tile's previous gather
// left (PassSpec::tile_state). The next photon pass may run while a gather is out.
// vcm, per iteration k (one sample per pixel): the light subpaths of the iteration's samples (a
// Paths pass of the same samples as the Tile pass after it: light tracing splats, and records that
// feed iteration k's light vertex map); then the camera subpaths (a Tile pass, a barrier) that
// merge with that map. Without merging, vcm's program is bdpt's.
// Either artifact is its records concatenated in unit order and sorted into a PointGrid.
#pragma once

#include "tessera/render/point_grid.h"
#include "tessera/render/scene.h"
#include "tessera/render/sppm.h"
#include "tessera/render/vcm.h"
#include "tessera/sequence/artifact.h"
#include "tessera/sequence/pass_program.h"
#include "tessera/sequence/pass_sequencer.h"

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace tessera {

/// Passes an sppm render of `spp` samples per pixel has: one per sample, capped by the scene's
/// maxPasses.
uint32_t sppm_passes(const IntegratorSettings& settings, uint32_t spp);

/// sppm's program: `passes` passes of `photons` photons each.
PassProgram photon_program(uint32_t passes, uint64_t photons);
/// vcm's program of `spp` iterations over a window of `window_pixels` (merging on; else
/// path_program's bdpt program).
PassProgram vcm_program(uint32_t spp, uint64_t window_pixels);

/// What makes the maps of a render whose passes feed them (sppm's photons, vcm's light vertices
/// with merging on), kept with a farm job's plan so that a coordinator that never loads the scene
/// builds them: the kind of record and each iteration's largest query radius.
struct PointMapPlan {
  IntegratorType type = IntegratorType::Sppm;
  float initial_radius = 0.f;  // sppm_initial_radius, or vcm_initial_radius
  float alpha = 0.f;           // vcm's radius reduction (sppm's radius per pixel is not the map's)
  /// Iteration k's largest query radius: sppm's initial radius (a pixel's only shrinks), vcm's r_k.
  float radius(uint32_t iteration) const;
  bool operator==(const PointMapPlan&) const = default;
};

/// The scene's plan, or none when its passes feed no map (not sppm, or vcm without merging).
std::optional<PointMapPlan> point_map_plan(const Scene& scene);

/// The program of a light-vertex render of `scene` (uses_light_vertex_passes): sppm's, vcm's, or
/// (vcm without merging) bdpt's.
PassProgram light_vertex_program(const Scene& scene, uint32_t spp, uint64_t window_pixels);

/// A pass's points (photons or light vertices) as an artifact: its bytes are the grid's largest
/// query radius (a little-endian float) and the records in the pass's order, zstd-compressed.
template <typename R>
class GridArtifact final : public Artifact {
 public:
  explicit GridArtifact(PointGrid<R> grid) : grid_(std::move(grid)) {}
  std::string encode() const override;
  size_t memory_bytes() const override { return grid_.memory_bytes(); }
  const PointGrid<R>& grid() const { return grid_; }

 private:
  PointGrid<R> grid_;
};
using PhotonMapArtifact = GridArtifact<Photon>;
using LightVertexArtifact = GridArtifact<LightVertexRecord>;

/// The same bytes from the records alone, never sorted into a grid: what a coordinator holds,
/// which only stores and hands out a map. Made under its lock by moving the units' records;
/// concatenated and compressed by encode(), off it.
class PointRecordsArtifact final : public Artifact {
 public:
  PointRecordsArtifact(float radius, std::vector<std::string> records) : radius_(radius), records_(std::move(records)) {}
  std::string encode() const override;
  size_t memory_bytes() const override;

 private:
  float radius_;
  std::vector<std::string> records_;  // per unit, in unit order
};

/// Whether a builder's artifacts carry their grid (a renderer gathers from them) or only their
/// records (a coordinator).
enum class PointMapUse { Render, Store };

/// Makes iteration k's map from the records of the units that feed it, in unit order, for
/// queries of radius up to radius(k). check_records() checks what is cheap (the iteration, whole
/// records, the cap); every record's values are checked by check_point_records() where the
/// records arrive, and again by decode().
template <typename R>
class GridBuilder final : public ArtifactBuilder {
 public:
  explicit GridBuilder(std::function<float(uint32_t)> radius, PointMapUse use = PointMapUse::Render)
      : radius_(std::move(radius)), use_(use) {}
  std::shared_ptr<const Artifact> build(uint32_t iteration) override;
  [[nodiscard]] bool check_records(uint32_t iteration, std::string_view records, std::string& error) const override;
  void add_records(uint32_t iteration, uint64_t unit, std::string_view records) override;
  std::shared_ptr<const Artifact> decode(std::string_view bytes, std::string& error) const override;
  void restore(uint32_t iteration, std::shared_ptr<const Artifact> artifact) override;
  void release() override {
    records_.clear();
    bytes_ = 0;
  }

 private:
  std::function<float(uint32_t)> radius_;
  PointMapUse use_;
  uint32_t next_ = 0;                        // the iteration being fed
  std::map<uint64_t, std::string> records_;  // by unit
  uint64_t bytes_ = 0;                       // of records_
};

/// Whether `records` are whole, finite, in-range records of the kind a `type` render's passes
/// feed, within the cap (kMaxPhotonMapBytes).
[[nodiscard]] bool check_point_records(IntegratorType type, std::string_view records, std::string& error);
/// A stored or downloaded map of a `type` render, with its grid; null with `error` if the bytes
/// are not one.
std::shared_ptr<const Artifact> decode_point_map(IntegratorType type, std::string_view bytes, std::string& error);
/// Whether `state` is sppm's per-pixel state (SppmPixel, finite and in range) of `pixels` pixels.
[[nodiscard]] bool check_sppm_state(std::string_view state, size_t pixels, std::string& error);

/// The records of a unit: its points' bytes.
template <typename R>
std::string grid_records(const std::vector<R>& points) {
  return std::string(reinterpret_cast<const char*>(points.data()), points.size() * sizeof(R));
}

/// The sequencer of an sppm or vcm render of `scene` over `frame` (`spp` samples per pixel).
PassSequencer light_vertex_sequencer(const Scene& scene, uint32_t spp, const SequenceFrame& frame);
/// The sequencer of a planned light-vertex program (a farm job's), its maps made per `plan` (none:
/// vcm without merging, bdpt's program).
PassSequencer light_vertex_sequencer(PassProgram program, const SequenceFrame& frame,
                                     const std::optional<PointMapPlan>& plan, PointMapUse use);

/// Renders one unit of such a program into `result`: a photon range's records, a light path
/// range's splats and records, a gather tile (its film tile and the state its pixels leave) or a
/// camera tile that merges. `artifact`: the one the unit renders with. The one way `tessera
/// render` and a farm worker do it.
void render_light_vertex_unit(const Scene& scene, const Artifact* artifact, const UnitWork& work, uint32_t seed,
                              UnitResult& result);

}  // namespace tessera
