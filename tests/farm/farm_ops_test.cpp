// Operating the farm: jobs that stop at a target noise level, webhooks called when jobs end, and
// animations rendered as one job per frame. Every image is compared bit for bit with a local render.
#include "farm_harness.h"

#include <httplib.h>

#include <mutex>

namespace tessera::test {
namespace {

using nlohmann::json;

std::string animation() { return std::string(TESSERA_SOURCE_DIR) + "/scenes/animation/scene.xml"; }

// Posts settings + the scene's bundle (as tessera submit does), with extra fields merged in.
client::HttpReply post_job(const Farm& farm, const std::string& scene, JobSettings settings, const json& extra) {
  auto abs = std::filesystem::absolute(scene);
  LoadedJobScene loaded = load_job_scene(abs.parent_path().string(), abs.filename().string(), settings, false);
  BundlePlan plan = plan_bundle(abs.string(), scene_files(loaded.desc, loaded.loaded));
  settings.scene_file = plan.files.front();
  json body = to_json(settings);
  body.erase("scene");
  body.update(extra);
  return farm.api().submit_job(body, pack_bundle(plan.root_dir, plan.files));
}

double rel_mse(const Image& x, const Image& ref) {
  double sum = 0;
  for (size_t i = 0; i < x.values().size(); ++i) {
    const double d = double(x.values()[i]) - ref.values()[i];
    sum += d * d / (double(ref.values()[i]) * ref.values()[i] + 0.01);
  }
  return sum / double(x.values().size());
}

TEST(FarmOps, JobStopsAtItsTargetNoiseAtAPassBoundary) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker(2);
  JobSettings s;
  s.spp = 4096;  // the budget; the target should stop it long before
  s.width = 40;
  s.height = 30;
  s.tile_size = 16;
  s.target_error = 0.02;
  const uint64_t id = farm.submit(cornell(), s);
  ASSERT_GT(id, 0u);
  json st = farm.wait_job(id, 300);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump();
  EXPECT_TRUE(st["stopped_at_target"].get<bool>());
  const int spp = st["spp_done"].get<int>();
  EXPECT_GT(spp, 1);
  EXPECT_LT(spp, 4096);
  ASSERT_TRUE(st["noise_estimate"].is_number());
  EXPECT_LE(st["noise_estimate"].get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(st["progress"].get<double>(), 1.0);
  EXPECT_GT(st["samples_per_second"].get<double>(), 0);

  // The image is `tessera render` at the spp reached, bit for bit.
  JobSettings reached = s;
  reached.spp = spp;
  reached.target_error = 0;
  ImageAttributes header;
  const Image image = farm.image(id, &header);
  EXPECT_EQ(differing_pixels(image, local_render(cornell(), reached)), 0);
  EXPECT_EQ(header["tessera_spp"], std::to_string(spp)) << "the EXR header names the spp reached, not the budget";
  // And `tessera render --target-error` with the same budget stops at the same pass.
  EXPECT_EQ(differing_pixels(image, local_render(cornell(), s)), 0);
  // And the estimate is an estimate of the truth (printed, judged by people: bench/convergence.sh measures it).
  JobSettings converged = s;
  converged.spp = 1024;
  converged.target_error = 0;
  std::printf("target 0.02: stopped at %d spp, estimate %.4f, true relMSE against 1024 spp %.4f\n", spp,
              st["noise_estimate"].get<double>(), rel_mse(image, local_render(cornell(), converged)));

  // A job without a target carries the estimate too, and renders every sample.
  s.target_error = 0;
  s.spp = 16;
  const uint64_t plain = farm.submit(cornell(), s);
  json p = farm.wait_job(plain);
  EXPECT_FALSE(p["stopped_at_target"].get<bool>());
  EXPECT_EQ(p["spp_done"].get<int>(), 16);
  EXPECT_TRUE(p["noise_estimate"].is_number());
}

// A receiver for webhooks on a free loopback port.
struct HookReceiver {
  HookReceiver() {
    server.Post("/hook", [this](const httplib::Request& req, httplib::Response& res) {
      std::lock_guard<std::mutex> lock(mu);
      bodies.push_back(json::parse(req.body, nullptr, false));
      res.status = 204;
    });
    port = server.bind_to_any_port("127.0.0.1");
    thread = std::thread([this] { server.listen_after_bind(); });
  }
  ~HookReceiver() {
    server.stop();
    thread.join();
  }
  std::vector<json> wait_for(size_t n, double seconds) {
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      {
        std::lock_guard<std::mutex> lock(mu);
        if (bodies.size() >= n) return bodies;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::lock_guard<std::mutex> lock(mu);
    return bodies;
  }
  httplib::Server server;
  std::mutex mu;
  std::vector<json> bodies;
  int port = 0;
  std::thread thread;
};

TEST(FarmOps, WebhooksAreCalledWhenJobsEnd) {
  TESSERA_REQUIRE_FILE(cornell());
  HookReceiver hooks;
  ASSERT_GT(hooks.port, 0);
  const std::string url = "http://127.0.0.1:" + std::to_string(hooks.port) + "/hook";
  Farm farm({"--webhook-allow", "http://127.0.0.1:"});
  farm.start_server();
  JobSettings s;
  s.spp = 4;
  s.width = 32;
  s.height = 24;
  s.webhook = url;
  // Refused before anything runs: a webhook outside the allowed prefixes.
  client::HttpReply refused;
  JobSettings elsewhere = s;
  elsewhere.webhook = "http://169.254.169.254/latest";
  EXPECT_EQ(farm.submit(cornell(), elsewhere, &refused), 0u);
  EXPECT_EQ(refused.status, 422) << refused.body;

  const uint64_t cancelled = farm.submit(cornell(), s);  // no worker yet: it waits, and is cancelled
  ASSERT_GT(cancelled, 0u);
  ASSERT_TRUE(farm.client().del("/api/v1/jobs/" + std::to_string(cancelled)).ok());
  farm.add_worker();
  const uint64_t done = farm.submit(cornell(), s);
  ASSERT_EQ(farm.wait_job(done).value("state", ""), "done");
  std::vector<json> got = hooks.wait_for(2, 30);
  ASSERT_EQ(got.size(), 2u);
  std::map<uint64_t, std::string> states;
  for (const json& j : got) {
    ASSERT_TRUE(j.is_object());
    states[j["id"].get<uint64_t>()] = j["state"].get<std::string>();
  }
  EXPECT_EQ(states[cancelled], "cancelled");
  EXPECT_EQ(states[done], "done");
  // (The sender counts a delivery once the receiver's answer is back, a moment after it arrived.)
  bool counted = false;
  for (int i = 0; i < 100 && !counted; ++i) {
    counted = farm.client().get("/metrics").body.find("tessera_webhooks_total{result=\"delivered\"} 2") != std::string::npos;
    if (!counted) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(counted);
}

TEST(FarmOps, FrameRangesRenderOneJobPerFrame) {
  Farm farm;
  farm.start_server();
  farm.add_worker(2);
  JobSettings s;
  s.spp = 4;
  s.width = 48;
  s.height = 36;
  client::HttpReply r = post_job(farm, animation(), s, json{{"frames", "1-3"}, {"name", "roll"}});
  ASSERT_EQ(r.status, 201) << r.body;
  json jobs = r.json()["jobs"];
  ASSERT_EQ(jobs.size(), 3u);
  std::vector<Image> images;
  for (int k = 0; k < 3; ++k) {
    const uint64_t id = jobs[size_t(k)]["id"].get<uint64_t>();
    EXPECT_EQ(jobs[size_t(k)]["name"], "roll frame " + std::to_string(k + 1));
    ASSERT_EQ(farm.wait_job(id).value("state", ""), "done");
    JobSettings frame = s;
    frame.defines["frame"] = std::to_string(k + 1);
    images.push_back(farm.image(id));
    EXPECT_EQ(differing_pixels(images.back(), local_render(animation(), frame)), 0) << "frame " << k + 1;
  }
  EXPECT_GT(differing_pixels(images[0], images[2]), 0) << "the frames differ";
  // Bad ranges are refused whole.
  for (const json& bad : {json("3-1"), json("x"), json::array({1})}) {
    client::HttpReply b = post_job(farm, animation(), s, json{{"frames", bad}});
    EXPECT_EQ(b.status, 400) << bad.dump() << " " << b.body;
  }
  // A well-formed range of too many frames is out of range: 422, like every number over its limit.
  client::HttpReply many = post_job(farm, animation(), s, json{{"frames", "1-100000"}});
  EXPECT_EQ(many.status, 422) << many.body;
}

}  // namespace
}  // namespace tessera::test
