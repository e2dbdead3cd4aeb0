// `tessera bench rays`: traces a ray file (../shared/docs/rayfile.md) against a BVH, reports the
// build time and Mrays/s per set, optionally writes the answers and compares them with a reference.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/accel/rayfile.h"

#include <ostream>
#include <string>
#include <vector>

namespace tessera {

struct BenchRaysOptions {
  std::vector<std::string> geometry;  // OBJ files and folders (soup order of rayfile.md)
  std::string rays;                   // ray file to trace
  std::string hits_out;               // when non-empty, the answers are written there
  std::string compare;                // when non-empty, reference hit file to compare against
  int threads = 0;                    // <= 0: all hardware threads
  int repeat = 1;                     // each set is traced this often; the median time counts
};

struct BenchSetResult {
  std::string name;
  RayQuery query = RayQuery::Closest;
  uint64_t count = 0;
  uint64_t hits = 0;           // rays that hit (closest) or are occluded
  double seconds = 0;          // median over the repeats
  double mrays_per_s = 0;
  bool compared = false;
  uint64_t disagree = 0;       // rays disagreeing with the reference (when compared)
  double disagree_fraction = 0;
};

struct BenchRaysResult {
  size_t primitives = 0;       // input primitives (0 when the BVH was given)
  double build_seconds = 0;    // 0 when the BVH was given
  BvhStats bvh;
  std::vector<BenchSetResult> sets;
  HitFile hits;                // the answers, set by set
};

/// Loads the OBJ soup of options.geometry, builds the BVH with options.threads threads (printing
/// `build triangles=N threads=T seconds=S ...`), then does what bench_rays_on() does.
/// Throws SceneError (geometry) or RayFileError (ray/hit files).
BenchRaysResult bench_rays(const BenchRaysOptions& options, std::ostream& out);

/// Traces options.rays against `bvh` (options.geometry is ignored): prints one line per set,
/// `rays set=NAME n=COUNT mrays_per_s=RATE`, writes options.hits_out, and with options.compare
/// prints `compare set=NAME disagree=K fraction=F` per set (agreement rule of rayfile.md).
/// This is the entry point for geometry loaded some other way (e.g. a scene's accelerator).
BenchRaysResult bench_rays_on(const Bvh& bvh, const BenchRaysOptions& options, std::ostream& out);

/// Traces one set with all threads of the current task arena; `hits` is resized to the set.
void trace_ray_set(const Bvh& bvh, const RaySet& set, std::vector<HitRecord>& hits);

}  // namespace tessera
