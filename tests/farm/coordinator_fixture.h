// Helpers for the coordinator's in-process tests: a tiny scene and its bundle, worker
// registration with this build's fingerprint, and delivering real renders of leased units.
#pragma once

#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/bundle.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/tile_result.h"
#include "tessera/image/image.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/server/coordinator.h"
#include "test_support.h"

#include <cstring>
#include <fstream>
#include <functional>
#include <optional>

namespace tessera::test {

inline constexpr const char* kXml = R"(<scene version="0.6.0">
  <sensor type="perspective"><float name="fov" value="45"/>
    <sampler type="independent"><integer name="sampleCount" value="5"/></sampler>
    <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="12"/></film>
  </sensor>
  <shape type="sphere"><point name="center" x="0" y="0" z="4"/></shape>
  <emitter type="constant"/>
</scene>)";

inline std::string bundle() {
  TempDir src;
  src.write("scene.xml", kXml);
  return pack_bundle(src.path.string(), {"scene.xml"});
}

inline uint64_t add_worker(server::Coordinator& c, const std::string& name) {
  const BuildFingerprint& fp = build_fingerprint();
  auto r = c.register_worker(WorkerHello{name, 1, 0, fp.version, fp.isa, fp.probe});
  EXPECT_TRUE(r.ok()) << r.status.detail;
  return r.value.id;
}

// A lease as the API sends it (null when there was none): what the tests inspect.
inline nlohmann::json lease_json(const server::Result<std::optional<Lease>>& r) {
  EXPECT_TRUE(r.ok()) << r.status.detail;
  return r.value ? to_json(*r.value) : nlohmann::json();
}

/// Submits `settings` as a client sends them (JSON) with `bundle`, parsed as the HTTP layer does.
inline server::Result<JobSubmission> submit(server::Coordinator& c, const nlohmann::json& settings,
                                            const std::string& bundle) {
  JobRequest request;
  std::string error;
  bool out_of_range = false;
  if (!job_request_from_json(settings, request, error, bundle.empty(), &out_of_range))
    return server::make_error(out_of_range ? server::Code::Unprocessable : server::Code::BadRequest, "bad_settings", error);
  return c.submit_job(request, bundle);
}

inline server::CoordinatorOptions options(const TempDir& dir) {
  server::CoordinatorOptions o;
  o.data_dir = (dir.path / "data").string();
  return o;
}

// Renders a leased unit for real (the scene's seed replaced by `seed`) as a tile result's bytes;
// with `seconds`, as a worker reporting that much render time would.
inline std::string render_unit(const nlohmann::json& lease_json, const Scene& scene, uint32_t seed,
                               std::optional<double> seconds = std::nullopt) {
  Lease lease;
  std::string error;
  EXPECT_TRUE(lease_from_json(lease_json, lease, error)) << error;
  lease.settings.seed = seed;
  TileResult result = render_lease(scene, lease);
  if (seconds) result.seconds = *seconds;
  return encode_tile_result(result);
}

// Leases and delivers one unit for real; false when there was nothing to lease.
inline bool deliver_one(server::Coordinator& c, uint64_t worker, const Scene& scene, uint32_t seed) {
  nlohmann::json l = lease_json(c.lease(worker, 0));
  if (!l.is_object()) return false;
  auto up = c.upload_result(worker, l["id"], render_unit(l, scene, seed));
  EXPECT_TRUE(up.ok()) << up.status.detail;
  return true;
}

/// Submits `settings` with `bundle` to a coordinator in `dir` and delivers its units (rendered by
/// `render`, given the coordinator and the lease) until the job is done, stopping the coordinator
/// and starting it again every 2 to 6 results. Returns the job's id; `restarts` counts them.
inline uint64_t render_with_restarts(const TempDir& dir, const nlohmann::json& settings, const std::string& bundle,
                                     const std::function<std::string(server::Coordinator&, const nlohmann::json&)>& render,
                                     int& restarts) {
  uint64_t id = 0, worker = 0;
  restarts = 0;
  for (int round = 0; round < 500; ++round) {
    server::Coordinator c(options(dir));
    if (round == 0) {
      worker = add_worker(c, "w");
      auto job = submit(c, settings, bundle);
      if (!job.ok()) {
        ADD_FAILURE() << job.status.detail;
        return 0;
      }
      id = job.value.jobs.at(0).id;
    } else {
      ++restarts;
    }
    for (int i = 0; i < 2 + round % 5; ++i) {
      if (c.job_status(id).value.state == "done") return id;
      nlohmann::json l = lease_json(c.lease(worker, 5));  // (waits while a pass is being opened)
      if (!l.is_object()) break;
      auto up = c.upload_result(worker, l["id"], render(c, l));
      EXPECT_TRUE(up.ok()) << up.status.detail;
    }
  }
  ADD_FAILURE() << "the job does not finish";
  return id;
}

/// A job's plan for a scene loaded in the test (its film), without the coordinator.
inline JobPlan plan_for(const Scene& scene, int spp, int tile_size, uint32_t seed) {
  JobPlan plan;
  plan.settings.spp = spp;
  plan.settings.tile_size = tile_size;
  plan.settings.seed = seed;
  plan.window = film_window(scene.film);
  plan.full_width = scene.film.width;
  plan.full_height = scene.film.height;
  return plan;
}

/// Pixels whose sums differ in any bit (films of one window).
inline int64_t differing(const Film& a, const Film& b) {
  int64_t n = 0;
  const TileRect& w = a.window();
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) n += std::memcmp(&a.pixel({x, y}), &b.pixel({x, y}), sizeof(PixelSums)) != 0;
  return n;
}

/// A job image's PFM bytes (Coordinator::job_image), decoded.
inline Image pfm_image(const std::string& bytes) {
  TempDir dir;
  const std::string path = (dir.path / "image.pfm").string();
  std::ofstream(path, std::ios::binary) << bytes;
  return read_image(path);
}

}  // namespace tessera::test
