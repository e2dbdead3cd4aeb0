// Intel Embree 3 on the same ray file and triangle soup as `tessera bench rays`, for a side-by-side
// figure on one machine in one run (bench/embree_compare.sh). A benchmark comparator only: the
// product never links Embree. Prints the same line format as bench rays, plus the agreement with
// the hit file when --compare is given. Asserts nothing.
#include "tessera/accel/obj_soup.h"
#include "tessera/accel/rayfile.h"

#include <CLI/CLI.hpp>
#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
using tessera::HitRecord;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

/// Builds the scene on `threads` threads with the given quality; returns the build seconds.
double build(EmbreeScene& es, const std::vector<std::array<tessera::Vec3, 3>>& tris, int threads,
             RTCBuildQuality quality, const std::string& extra_config) {
  std::string config = "threads=" + std::to_string(threads) + ",set_affinity=0";
  if (!extra_config.empty()) config += "," + extra_config;
  es.device = rtcNewDevice(config.c_str());
  if (!es.device) throw std::runtime_error("rtcNewDevice failed");
  const Clock::time_point start = Clock::now();
  es.scene = rtcNewScene(es.device);
  rtcSetSceneBuildQuality(es.scene, quality);
  RTCGeometry geom = rtcNewGeometry(es.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geom, quality);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), tris.size() * 3));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), tris.size()));
  for (size_t i = 0; i < tris.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      v[9 * i + 3 * k + 0] = tris[i][k].x;
      v[9 * i + 3 * k + 1] = tris[i][k].y;
      v[9 * i + 3 * k + 2] = tris[i][k].z;
      idx[3 * i + k] = unsigned(3 * i + k);
    }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(es.scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(es.scene);
  return seconds_since(start);
}

/// Traces one set on the calling thread, one rtcIntersect1/rtcOccluded1 per ray.
void trace(RTCScene scene, const tessera::RaySet& set, std::vector<HitRecord>& hits) {
  hits.assign(set.rays.size(), HitRecord{});
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  const bool occlusion = set.query == tessera::RayQuery::Occlusion;
  for (size_t i = 0; i < set.rays.size(); ++i) {
    const tessera::Ray& r = set.rays[i];
    RTCRayHit rh{};
    rh.ray.org_x = r.o.x, rh.ray.org_y = r.o.y, rh.ray.org_z = r.o.z;
    rh.ray.dir_x = r.d.x, rh.ray.dir_y = r.d.y, rh.ray.dir_z = r.d.z;
    rh.ray.tnear = r.tmin;
    rh.ray.tfar = r.tmax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    if (occlusion) {
      rtcOccluded1(scene, &ctx, &rh.ray);
      if (rh.ray.tfar < 0.f) hits[i] = HitRecord{0.f, 0};
    } else {
      rtcIntersect1(scene, &ctx, &rh);
      if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) hits[i] = HitRecord{rh.ray.tfar, rh.hit.primID};
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> geometry;
  std::string rays_path, compare;
  int repeat = 3;
  std::vector<int> build_threads{1, 2};
  std::string extra_config;
  CLI::App app{"Embree 3 (rtcIntersect1/rtcOccluded1, one thread) on a ray file, for comparison"};
  app.add_option("geometry", geometry, "OBJ files or folders (folders: every *.obj, sorted)")->required();
  app.add_option("--rays", rays_path, "ray file")->required();
  app.add_option("--compare", compare, "reference hit file to compare against");
  app.add_option("--repeat", repeat, "trace each set this often; report the median");
  app.add_option("--build-threads", build_threads, "thread counts to time the build with");
  app.add_option("--config", extra_config, "more rtcNewDevice settings, e.g. isa=sse4.2");
  CLI11_PARSE(app, argc, argv);
  try {
    const tessera::ObjSoup soup = tessera::load_obj_soup(geometry);
    const tessera::RayFile rays = tessera::read_ray_file(rays_path);
    tessera::HitFile reference;
    if (!compare.empty()) reference = tessera::read_hit_file(compare);
    for (int threads : build_threads)
      for (RTCBuildQuality q : {RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_HIGH}) {
        std::vector<double> times;
        for (int rep = 0; rep < std::max(1, repeat); ++rep) {
          EmbreeScene es;
          times.push_back(build(es, soup.triangles, threads, q, extra_config));
        }
        std::sort(times.begin(), times.end());
        std::printf("embree build triangles=%zu threads=%d quality=%s seconds=%.4f\n", soup.triangles.size(), threads,
                    q == RTC_BUILD_QUALITY_MEDIUM ? "medium" : "high", times[times.size() / 2]);
      }
    EmbreeScene es;  // the scene traced: medium quality, the default of rtcCommitScene
    build(es, soup.triangles, 1, RTC_BUILD_QUALITY_MEDIUM, extra_config);
    for (size_t s = 0; s < rays.sets.size(); ++s) {
      const tessera::RaySet& set = rays.sets[s];
      std::vector<HitRecord> hits;
      std::vector<double> times;
      for (int rep = 0; rep < std::max(1, repeat); ++rep) {
        const Clock::time_point start = Clock::now();
        trace(es.scene, set, hits);
        times.push_back(seconds_since(start));
      }
      std::sort(times.begin(), times.end());
      std::printf("embree rays set=%s n=%zu threads=1 mrays_per_s=%.3f\n", set.name.c_str(), set.rays.size(),
                  double(set.rays.size()) / times[times.size() / 2] * 1e-6);
      if (!compare.empty()) {
        uint64_t disagree = 0;
        for (size_t i = 0; i < hits.size(); ++i)
          if (!tessera::hits_agree(hits[i], reference.sets[s].hits[i])) ++disagree;
        std::printf("embree compare set=%s disagree=%llu\n", set.name.c_str(), (unsigned long long)disagree);
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "embree_rays: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
