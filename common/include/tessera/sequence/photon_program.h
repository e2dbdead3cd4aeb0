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

/// Makes iteration k's grid from the records of the units that feed it, in unit order, for
/// queries of radius up to radius(k).
template <typename R>
class GridBuilder final : public ArtifactBuilder {
 public:
  explicit GridBuilder(std::function<float(uint32_t)> radius) : radius_(std::move(radius)) {}
  std::shared_ptr<const Artifact> build(uint32_t iteration) override;
  [[nodiscard]] bool check_records(uint32_t iteration, std::string_view records, std::string& error) const override;
  void add_records(uint32_t iteration, uint64_t unit, std::string_view records) override;
  std::shared_ptr<const Artifact> decode(std::string_view bytes, std::string& error) const override;
  void restore(uint32_t iteration, std::shared_ptr<const Artifact> artifact) override;
  void release() override { records_.clear(); }

 private:
  std::function<float(uint32_t)> radius_;
  uint32_t next_ = 0;                        // the iteration being fed
  std::map<uint64_t, std::string> records_;  // by unit
};

/// The records of a unit: its points' bytes.
template <typename R>
std::string grid_records(const std::vector<R>& points) {
  return std::string(reinterpret_cast<const char*>(points.data()), points.size() * sizeof(R));
}

/// The sequencer of an sppm or vcm render of `scene` over `frame` (`spp` samples per pixel).
PassSequencer light_vertex_sequencer(const Scene& scene, uint32_t spp, const SequenceFrame& frame);

/// Renders one unit of such a program into `result`: a photon range's records, a light path
/// range's splats and records, a gather tile (its film tile and the state its pixels leave) or a
/// camera tile that merges. `artifact`: the one the unit renders with. The one way `tessera
/// render` and a farm worker do it.
void render_light_vertex_unit(const Scene& scene, const Artifact* artifact, const UnitWork& work, uint32_t seed,
                              UnitResult& result);

}  // namespace tessera
