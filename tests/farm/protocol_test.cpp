// Strict parsing of the farm's JSON messages.
#include "tessera/farm/protocol.h"
#include "tessera/farm/job_status.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using nlohmann::json;

std::string parse_error(const json& j, bool require_scene = true) {
  JobSettings s;
  std::string error;
  EXPECT_FALSE(job_settings_from_json(j, s, error, require_scene)) << j.dump();
  return error;
}

TEST(Protocol, JobSettingsRoundTrip) {
  JobSettings s;
  s.name = "x";
  s.scene = std::string(64, 'c');
  s.spp = 37;
  s.width = 100;
  s.height = 75;
  s.seed = 9;
  s.tile_size = 24;
  s.priority = -2;
  s.defines = {{"spp", "4"}, {"res", "hi"}};
  s.integrator = "volpath";
  s.light_selection = "power";
  s.target_error = 0.005;
  s.adaptive = true;
  s.webhook = "https://ci.example/hooks/render?x=1";
  JobSettings back;
  std::string error;
  ASSERT_TRUE(job_settings_from_json(to_json(s), back, error)) << error;
  EXPECT_EQ(to_json(back), to_json(s));
  EXPECT_TRUE(back.adaptive);
  EXPECT_FALSE(back.guiding.has_value()) << "null: as the scene says";
  s.guiding = false;
  ASSERT_TRUE(job_settings_from_json(to_json(s), back, error)) << error;
  EXPECT_EQ(back.guiding, std::optional<bool>(false));
}

// Every integrator the loader has is a job's "integrator"; anything else is refused by the limits
// check (the API's 422 bad_settings), naming the field.
TEST(Protocol, IntegratorNamesTheLoaderKnows) {
  JobLimits limits;
  for (const char* name : {"", "path", "volpath", "direct", "bdpt", "ptracer", "sppm", "vcm"}) {
    JobSettings s;
    std::string error;
    ASSERT_TRUE(job_settings_from_json(json{{"scene", std::string(64, 'a')}, {"integrator", name}}, s, error)) << error;
    EXPECT_EQ(s.integrator, name);
    EXPECT_TRUE(check_job_limits(s, limits, error)) << name << ": " << error;
  }
  JobSettings s;
  std::string error;
  ASSERT_TRUE(job_settings_from_json(json{{"scene", std::string(64, 'a')}, {"integrator", "bpdt"}}, s, error)) << error;
  EXPECT_FALSE(check_job_limits(s, limits, error));
  EXPECT_NE(error.find("job settings: integrator 'bpdt' is not path, volpath, direct, bdpt, ptracer, sppm or vcm"),
            std::string::npos)
      << error;
  EXPECT_NE(parse_error(json{{"scene", std::string(64, 'a')}, {"integrator", 3}}).find("'integrator'"), std::string::npos);
}

// A number its field cannot hold is out of range (the API's 422, as the limits), named with the
// range, whether it is negative, a fraction or beyond any JSON integer; a wrong type stays a
// malformed request (400).
TEST(Protocol, OutOfRangeNumbersNameTheFieldAndItsRange) {
  const std::string h(64, 'a');
  const auto range_error = [&](const std::string& body) {
    JobSettings s;
    std::string error;
    bool out_of_range = false;
    EXPECT_FALSE(job_settings_from_json(json::parse(body), s, error, true, &out_of_range)) << body;
    EXPECT_TRUE(out_of_range) << body << ": " << error;
    return error;
  };
  const std::string pre = "{\"scene\": \"" + h + "\", ";
  EXPECT_NE(range_error(pre + "\"spp\": 18446744073709551616}").find("'spp' must be an integer in -2147483648..2147483647"),
            std::string::npos);
  EXPECT_NE(range_error(pre + "\"spp\": 9223372036854775808}").find("'spp'"), std::string::npos);
  EXPECT_NE(range_error(pre + "\"spp\": 2.5}").find("'spp' must be an integer in"), std::string::npos);
  EXPECT_NE(range_error(pre + "\"seed\": -1}").find("'seed' must be an integer in 0..4294967295, not -1"), std::string::npos);
  EXPECT_NE(range_error(pre + "\"priority\": 1e30}").find("'priority'"), std::string::npos);
  EXPECT_NE(range_error(pre + "\"target_error\": 2}").find("'target_error' must be a relMSE in 0..1"), std::string::npos);
  JobSettings s;
  std::string error;
  bool out_of_range = true;
  EXPECT_FALSE(job_settings_from_json(json{{"scene", h}, {"spp", "many"}}, s, error, true, &out_of_range));
  EXPECT_FALSE(out_of_range) << "a string is malformed, not out of range";
  JobRequest request;
  std::string frames_error;
  EXPECT_FALSE(job_request_from_json(json::parse(pre + "\"frames\": \"1-2\", \"spp\": 2.5}"), request, frames_error,
                                     true, &out_of_range));
  EXPECT_TRUE(out_of_range) << "a frame range's settings are told apart alike";
}

// Every shared scene is scene.xml: an unnamed job is named after its folder.
TEST(Protocol, DefaultJobNameIsTheScenesFolder) {
  EXPECT_EQ(default_job_name("/scenes/cornell-box/scene.xml"), "cornell-box");
  EXPECT_EQ(default_job_name("cornell-box/scene.xml"), "cornell-box");
  EXPECT_EQ(default_job_name("/scenes/veach/mis.xml"), "veach-mis");
  EXPECT_EQ(default_job_name("/scenes/kitchen/kitchen.xml"), "kitchen");
  EXPECT_EQ(default_job_name("scene.xml"), "scene");
  EXPECT_EQ(default_job_name("cbox.xml"), "cbox");
}

TEST(Protocol, JobSettingsAreStrict) {
  const std::string h(64, 'a');
  EXPECT_NE(parse_error(json{{"scene", h}, {"spp_", 3}}).find("unknown field 'spp_'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"spp", 1.5}}).find("'spp' must be an integer"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"seed", -1}}).find("'seed'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"width", "10"}}).find("'width'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"defines", json::array()}}).find("'defines'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", "ABC"}}).find("hash"), std::string::npos);
  EXPECT_NE(parse_error(json{{"spp", 3}}).find("missing field 'scene'"), std::string::npos);
  EXPECT_NE(parse_error(json::array()).find("JSON object"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"target_error", -0.1}}).find("'target_error'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"target_error", 2}}).find("'target_error'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"target_error", "low"}}).find("'target_error'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"webhook", "file:///etc/passwd"}}).find("'webhook'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"webhook", 7}}).find("'webhook'"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"adaptive", "on"}}).find("'adaptive' must be true or false"), std::string::npos);
  EXPECT_NE(parse_error(json{{"scene", h}, {"guiding", 1}}).find("'guiding' must be true or false"), std::string::npos);
  JobSettings s;
  std::string error;
  EXPECT_TRUE(job_settings_from_json(json{{"spp", 3}}, s, error, /*require_scene=*/false)) << error;
  EXPECT_TRUE(job_settings_from_json(json{{"scene", h}, {"defines", {{"n", 3}}}}, s, error)) << error;
  EXPECT_EQ(s.defines.at("n"), "3");
}

TEST(Protocol, LimitsNameTheField) {
  JobLimits limits;
  JobSettings s;
  std::string error;
  EXPECT_TRUE(check_job_limits(s, limits, error)) << error;
  s.width = 1 << 20;
  EXPECT_FALSE(check_job_limits(s, limits, error));
  EXPECT_NE(error.find("width"), std::string::npos);
  s = {};
  s.spp = -1;
  EXPECT_FALSE(check_job_limits(s, limits, error));
  s = {};
  s.tile_size = 1;
  EXPECT_FALSE(check_job_limits(s, limits, error));
  s = {};
  s.integrator = "bpdt";
  EXPECT_FALSE(check_job_limits(s, limits, error));
  EXPECT_NE(error.find("integrator 'bpdt' is not path, volpath, direct, bdpt, ptracer, sppm or vcm"), std::string::npos) << error;
  s = {};
  s.width = s.height = 30000;
  EXPECT_FALSE(check_job_limits(s, limits, error));
  EXPECT_NE(error.find("pixels"), std::string::npos);
  // Tiles: 4096 x 4096 in 4-pixel tiles is 1M tiles, over a limit of 1000; 64-pixel tiles fit.
  s = {};
  s.width = s.height = 4096;
  s.tile_size = 4;
  limits.max_tiles = 1000;
  EXPECT_FALSE(check_job_limits(s, limits, error));
  EXPECT_NE(error.find("tiles"), std::string::npos) << error;
  s.tile_size = 256;
  EXPECT_TRUE(check_job_limits(s, limits, error)) << error;
}

TEST(Protocol, LeaseRoundTripAndCacheKey) {
  Lease l;
  l.id = 3;
  l.job_id = 4;
  l.tile = 5;
  l.pass = 6;
  l.rect = {0, 8, 16, 24};
  l.sample_begin = 7;
  l.sample_end = 15;
  l.settings.scene = std::string(64, 'd');
  l.scene_file = "sub/scene.xml";
  l.files = {"sub/scene.xml", "meshes/a.obj"};
  Lease back;
  std::string error;
  ASSERT_TRUE(lease_from_json(to_json(l), back, error)) << error;
  EXPECT_EQ(to_json(back), to_json(l));
  json bad = to_json(l);
  bad["rect"] = {1, 2};
  EXPECT_FALSE(lease_from_json(bad, back, error));
  // An adaptive pass's lease: each pixel's first sample and count.
  l.samples = PassSamples::uniform(l.rect, 7, 15);
  l.samples.count[3] = 20;
  error.clear();
  ASSERT_TRUE(lease_from_json(to_json(l), back, error)) << error;
  EXPECT_EQ(back.samples, l.samples);
  bad = to_json(l);
  bad["count"].erase(0);
  error.clear();
  EXPECT_FALSE(lease_from_json(bad, back, error));
  EXPECT_NE(error.find("one entry per pixel"), std::string::npos) << error;
  bad = to_json(l);
  bad["first"][0] = 4294967290u;
  EXPECT_FALSE(lease_from_json(bad, back, error));
  // An sppm gather's lease: its tile's per-pixel state, any bytes, base64 on the wire.
  Lease gather = l;
  gather.samples = {};
  gather.tile_state = std::string("\0\x01\xff state", 9) + std::string(100, '\x7f');
  error.clear();
  Lease gather_back;
  ASSERT_TRUE(lease_from_json(to_json(gather), gather_back, error)) << error;
  EXPECT_EQ(gather_back.tile_state, gather.tile_state);
  bad = to_json(gather);
  bad["tile_state"] = "not base64!";
  EXPECT_FALSE(lease_from_json(bad, gather_back, error));
  // A photon pass's lease: paths, and no pixel samples of its own.
  Lease photons = l;
  photons.samples = {};
  photons.paths = std::pair<uint64_t, uint64_t>{0, 4096};
  photons.sample_end = photons.sample_begin;
  error.clear();
  Lease photons_back;
  ASSERT_TRUE(lease_from_json(to_json(photons), photons_back, error)) << error;
  bad = to_json(photons);
  bad["tile_state"] = "AAAA";
  EXPECT_FALSE(lease_from_json(bad, photons_back, error)) << "state only on a lease of a tile";
  // The cache key changes with anything that changes the loaded scene, not with the seed.
  JobSettings a = l.settings, b = a;
  b.seed = 99;
  EXPECT_EQ(scene_cache_key(a, "s.xml"), scene_cache_key(b, "s.xml"));
  b.defines["x"] = "1";
  EXPECT_NE(scene_cache_key(a, "s.xml"), scene_cache_key(b, "s.xml"));
  EXPECT_NE(scene_cache_key(a, "s.xml"), scene_cache_key(a, "t.xml"));
}

// The coordinator counts a lease's JSON bytes from its own fields plus its job's part measured once:
// the same count as serializing the whole lease, for any lease of the job.
TEST(Protocol, LeaseBytesCountedFromTheJobPartAreExact) {
  Lease first;
  first.settings.scene = std::string(64, 'd');
  first.settings.defines["name"] = "caf\u00e9 \"quoted\"";
  first.scene_file = "sub/scene.xml";
  first.files = {"sub/scene.xml", "meshes/a.obj", "textures/\u00fcber.png"};
  const size_t job_part = lease_job_part_bytes(first);
  for (uint64_t id : {1ull, 99ull, 123456789012ull}) {
    Lease l = first;
    l.id = id;
    l.job_id = id * 7;
    l.tile = uint32_t(id % 1000);
    l.pass = uint32_t(id % 13);
    l.rect = {0, int(id % 100), 32, int(id % 100) + 32};
    l.sample_begin = 3;
    l.sample_end = uint32_t(id % 77) + 4;
    l.seconds_to_expiry = id == 1 ? 15.0 : 7.25;
    if (id == 99) l.tile_state = std::string(size_t(id), 's');  // (an sppm gather's)
    EXPECT_EQ(lease_json_bytes(l, job_part), to_json(l).dump().size()) << id;
  }
}

TEST(Protocol, HeartbeatsRoundTripAndAreStrict) {
  Heartbeat held;
  held.leases = {{31, 1, 5, 2}, {32, 1, 6, 2}};
  held.memory = WorkerMemory{uint64_t(5) << 32, 3};
  Heartbeat back;
  std::string error;
  ASSERT_TRUE(heartbeat_from_json(heartbeat_to_json(held), back, error)) << error;
  ASSERT_EQ(back.leases.size(), 2u);
  EXPECT_EQ(back.leases[1].id, 32u);
  EXPECT_EQ(back.leases[1].tile, 6u);
  ASSERT_TRUE(back.memory.has_value());
  EXPECT_EQ(back.memory->scene_bytes, uint64_t(5) << 32);
  EXPECT_EQ(back.memory->scenes, 3u);
  ASSERT_TRUE(heartbeat_from_json(json::object(), back, error)) << "no leases held, no memory reported";
  EXPECT_TRUE(back.leases.empty());
  EXPECT_FALSE(back.memory.has_value());
  auto refused = [&](const json& j, const std::string& why) {
    std::string e;
    Heartbeat out;
    EXPECT_FALSE(heartbeat_from_json(j, out, e)) << j.dump().substr(0, 80);
    EXPECT_NE(e.find(why), std::string::npos) << e;
  };
  refused(json::array(), "expected a JSON object");
  refused(json{{"leases", json::array()}, {"junk", 1}}, "unknown field 'junk'");
  refused(json{{"leases", "x"}}, "'leases' must be an array");
  refused(json{{"memory", {{"scene_bytes", -1}, {"scenes", 0}}}}, "'scene_bytes' must be an integer in 0..");
  refused(json{{"memory", {{"scenes", 1}}}}, "missing field 'scene_bytes'");
  refused(json{{"leases", {{{"id", 1}, {"job", 1}, {"tile", 0}}}}}, "missing field 'pass'");
  refused(json{{"leases", {{{"id", -1}, {"job", 1}, {"tile", 0}, {"pass", 0}}}}}, "field 'id'");
  refused(json{{"leases", {{{"id", 1}, {"job", 1}, {"tile", 0}, {"pass", 0}, {"extra", 0}}}}}, "unknown field 'extra'");
  json many = json::array();
  for (size_t i = 0; i <= kMaxHeldLeases; ++i) many.push_back({{"id", i}, {"job", 1}, {"tile", 0}, {"pass", 0}});
  refused(json{{"leases", many}}, "at most");
}

TEST(JobStatus, JsonNamesEveryFieldAndLeavesOutWhatIsUnknown) {
  JobStatus st;
  st.id = 7;
  st.state = "running";
  st.units_done = 3;
  st.workers.push_back({2, "w", 64, 1.0});
  json j = to_json(st);
  EXPECT_EQ(j["id"], 7);
  EXPECT_EQ(j["state"], "running");
  EXPECT_EQ(j["units_done"], 3);
  EXPECT_EQ(j["workers"][0]["name"], "w");
  EXPECT_TRUE(j["noise_estimate"].is_null()) << "null until every pixel has two samples";
  EXPECT_FALSE(j.contains("leases_issued")) << "left out when the lease log could not be read";
  st.noise_estimate = 0.25;
  st.leases_issued = 5;
  st.reissued_acknowledged_passes = 0;
  j = to_json(st);
  EXPECT_EQ(j["noise_estimate"], 0.25);
  EXPECT_EQ(j["leases_issued"], 5);
  EXPECT_EQ(j["reissued_acknowledged_passes"], 0);
  EXPECT_EQ(j["settings"], to_json(st.settings));
}

TEST(JobStatus, ASubmissionIsTheJobsStatusOrOnePerFrame) {
  JobStatus a, b;
  a.id = 1;
  b.id = 2;
  EXPECT_EQ(to_json(JobSubmission{{a}, std::nullopt}), to_json(a));
  const json frames = to_json(JobSubmission{{a, b}, std::pair{10, 11}});
  ASSERT_EQ(frames["jobs"].size(), 2u);
  EXPECT_EQ(frames["jobs"][1]["id"], 2);
  EXPECT_EQ(frames["frames"], json::array({10, 11}));
}

}  // namespace
}  // namespace tessera
