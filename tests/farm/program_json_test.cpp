// A job's passes kept in its plan (farm/program_json.h): every field round trips; a program that
// is not sound, or JSON that is not one, is refused naming why.
#include "tessera/farm/job_scene.h"
#include "tessera/farm/program_json.h"
#include "tessera/sequence/path_program.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace tessera::test {
namespace {

void expect_round_trip(const PassProgram& p) {
  ASSERT_EQ(program_error(p), "");
  PassProgram back;
  std::string error;
  ASSERT_TRUE(program_from_json(nlohmann::json::parse(to_json(p).dump()), back, error)) << error;
  ASSERT_EQ(back.passes.size(), p.passes.size());
  for (size_t i = 0; i < p.passes.size(); ++i) EXPECT_TRUE(back.passes[i] == p.passes[i]) << "pass " << i;
  EXPECT_EQ(back.spp, p.spp);
  EXPECT_EQ(back.paths_per_unit, p.paths_per_unit);
  EXPECT_EQ(back.target_error, p.target_error);
  EXPECT_EQ(back.films, p.films);
  EXPECT_EQ(back.combine, p.combine);
  EXPECT_EQ(back.adaptive_settings.min_samples, p.adaptive_settings.min_samples);
  EXPECT_EQ(back.adaptive_settings.uniform_fraction, p.adaptive_settings.uniform_fraction);
  EXPECT_EQ(back.adaptive_settings.max_factor, p.adaptive_settings.max_factor);
}

TEST(ProgramJson, RoundTripsEveryField) {
  PathProgramOptions o;
  o.spp = 40;
  o.target_error = 0.01;
  o.adaptive = true;
  o.guide = GuidePlan{};
  expect_round_trip(path_program(o));  // (barriers, stops, adaptive passes, guides used and fed, a film skipped)
  PassProgram paths;
  paths.spp = 7;
  paths.films = 2;
  paths.combine = FilmCombine::InverseVariance;
  paths.paths_per_unit = 999;
  paths.passes = {PassSpec{UnitKind::Tile, 0, 2},
                  PassSpec{UnitKind::Tile, 2, 2, false, false, false, 1, std::nullopt, std::nullopt, true},
                  PassSpec{UnitKind::Paths, 4, 3, false, false, false, 1}};
  expect_round_trip(paths);
  PathProgramOptions light;  // a light tracer's: each Tile pass and its light paths
  light.spp = 8;
  light.light_paths = true;
  const PassProgram traced = path_program(light);
  ASSERT_TRUE(std::any_of(traced.passes.begin(), traced.passes.end(), [](const PassSpec& p) { return p.same_samples; }));
  expect_round_trip(traced);
}

TEST(ProgramJson, UnsoundOrMalformedProgramsAreRefused) {
  PathProgramOptions o;
  o.spp = 8;
  const nlohmann::json good = to_json(path_program(o));
  PassProgram out;
  std::string error;
  auto refused = [&](nlohmann::json j, const std::string& why) {
    error.clear();
    EXPECT_FALSE(program_from_json(j, out, error)) << j.dump();
    EXPECT_NE(error.find(why), std::string::npos) << error;
  };
  nlohmann::json gap = good;
  gap["passes"][1]["sample_begin"] = 2;
  refused(gap, "do not follow");
  nlohmann::json kind = good;
  kind["passes"][0]["kind"] = "photons";
  refused(kind, "photons");
  nlohmann::json extra = good;
  extra["passes"][0]["junk"] = 1;
  refused(extra, "eleven fields");
  nlohmann::json total = good;
  total["spp"] = 9;
  refused(total, "add up to spp");
  refused(nlohmann::json::array(), "seven fields");
  nlohmann::json barrier = good;
  barrier["passes"][2]["adaptive"] = true;
  refused(barrier, "no barrier");
}

}  // namespace
}  // namespace tessera::test
