#include "tessera/tools/bench_rays.h"

#include "tessera/accel/obj_soup.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace tessera {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

tbb::task_arena make_arena(int threads) {
  return tbb::task_arena(threads > 0 ? threads : tbb::task_arena::automatic);
}

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

}  // namespace

void trace_ray_set(const Bvh& bvh, const RaySet& set, std::vector<HitRecord>& hits) {
  hits.resize(set.rays.size());
  const bool occlusion = set.query == RayQuery::Occlusion;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Ray& ray = set.rays[i];
      HitRecord rec;  // miss / free
      if (occlusion) {
        if (bvh.occluded(ray)) rec = HitRecord{0.f, 0};
      } else {
        Hit hit;
        if (bvh.intersect(ray, hit)) rec = HitRecord{hit.t, hit.prim};
      }
      hits[i] = rec;
    }
  });
}

BenchRaysResult bench_rays_on(const Bvh& bvh, const BenchRaysOptions& options, std::ostream& out) {
  const RayFile rays = read_ray_file(options.rays);
  HitFile reference;
  if (!options.compare.empty()) {
    reference = read_hit_file(options.compare);
    check_hits_match_rays(rays, reference, options.compare);
  }

  BenchRaysResult result;
  result.bvh = bvh.stats();
  result.hits.info = "tessera " TESSERA_VERSION " bench rays; rays: " + rays.info;
  tbb::task_arena arena = make_arena(options.threads);
  const int repeat = std::max(1, options.repeat);
  for (size_t s = 0; s < rays.sets.size(); ++s) {
    const RaySet& set = rays.sets[s];
    HitSet hit_set{set.name, set.query, {}};
    std::vector<double> times;
    for (int rep = 0; rep < repeat; ++rep) {
      const Clock::time_point start = Clock::now();
      arena.execute([&] { trace_ray_set(bvh, set, hit_set.hits); });
      times.push_back(seconds_since(start));
    }
    std::sort(times.begin(), times.end());

    BenchSetResult r;
    r.name = set.name;
    r.query = set.query;
    r.count = set.rays.size();
    r.hits = uint64_t(std::count_if(hit_set.hits.begin(), hit_set.hits.end(),
                                    [](const HitRecord& h) { return h.is_hit(); }));
    r.seconds = times[times.size() / 2];
    r.mrays_per_s = r.seconds > 0 ? double(r.count) / r.seconds * 1e-6 : 0.0;
    out << "rays set=" << r.name << " n=" << r.count << " mrays_per_s=" << format("%.3f", r.mrays_per_s)
        << "\n";
    if (!options.compare.empty()) {
      const std::vector<HitRecord>& ref = reference.sets[s].hits;
      for (size_t i = 0; i < ref.size(); ++i)
        if (!hits_agree(hit_set.hits[i], ref[i])) ++r.disagree;
      r.compared = true;
      r.disagree_fraction = r.count ? double(r.disagree) / double(r.count) : 0.0;
      out << "compare set=" << r.name << " disagree=" << r.disagree
          << " fraction=" << format("%.3g", r.disagree_fraction) << "\n";
    }
    result.sets.push_back(r);
    result.hits.sets.push_back(std::move(hit_set));
  }
  out.flush();
  if (!options.hits_out.empty()) write_hit_file(options.hits_out, result.hits);
  return result;
}

BenchRaysResult bench_rays(const BenchRaysOptions& options, std::ostream& out) {
  ObjSoup soup = load_obj_soup(options.geometry);
  const size_t num_triangles = soup.triangles.size();
  tbb::task_arena arena = make_arena(options.threads);
  Bvh bvh;
  const Clock::time_point start = Clock::now();
  arena.execute([&] { bvh = Bvh::build(std::move(soup.triangles), {}); });
  const double build_seconds = seconds_since(start);
  const BvhStats stats = bvh.stats();
  out << "build triangles=" << num_triangles << " threads=" << arena.max_concurrency()
      << " seconds=" << format("%.4f", build_seconds) << " nodes=" << stats.nodes
      << " leaves=" << stats.leaves << " max_depth=" << stats.max_depth
      << " sah_cost=" << format("%.2f", stats.sah_cost)
      << " mbytes=" << format("%.1f", double(stats.bytes) / (1024.0 * 1024.0)) << "\n";

  BenchRaysResult result = bench_rays_on(bvh, options, out);
  result.primitives = num_triangles;
  result.build_seconds = build_seconds;
  return result;
}

}  // namespace tessera
