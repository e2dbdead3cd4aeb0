// The `guided_path` integrator (Müller's Mitsuba 0.6 plugin): its parameters map onto the guiding
// settings, time budgets are refused, bad values name the file, line and parameter, and options
// Tessera does not implement are reported as unsupported with their fallback.
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <string>

namespace tessera {
namespace {

std::string scene_with(const std::string& params) {
  return "<scene version=\"0.6.0\">\n<integrator type=\"guided_path\">\n" + params +
         "</integrator>\n<sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sampleCount\" "
         "value=\"4\"/></sampler><film type=\"hdrfilm\"/></sensor>\n<shape type=\"sphere\"/>\n</scene>";
}

LoadResult load(const std::string& params, bool allow_unsupported = false) {
  LoadOptions options;
  options.allow_unsupported = allow_unsupported;
  return load_scene(parse_scene_string(scene_with(params), "mem/guided.xml"), options);
}

std::string error_of(const std::string& params) {
  try {
    (void)load(params);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for " << params;
  return "";
}

const std::string kSpp = "<string name=\"budgetType\" value=\"spp\"/>\n<float name=\"budget\" value=\"64\"/>\n";

TEST(GuidedPathLoader, MapsThePluginsParameters) {
  LoadResult r = load(kSpp + R"(<string name="sampleCombination" value="discard"/>
<string name="bsdfSamplingFractionLoss" value="kl"/>
<float name="bsdfSamplingFraction" value="0.4"/>
<integer name="sTreeThreshold" value="4000"/>
<float name="dTreeThreshold" value="0.02"/>
<integer name="sdTreeMaxMemory" value="64"/>
<string name="nee" value="always"/>
<string name="roulette" value="guided"/>
<string name="spatialFilter" value="stochastic"/>
<string name="directionalFilter" value="box"/>
<integer name="maxDepth" value="5"/>
)");
  const IntegratorSettings& s = r.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Path);
  EXPECT_EQ(s.max_depth, 5);
  ASSERT_TRUE(s.guiding.has_value());
  EXPECT_TRUE(s.guiding->learn_bsdf_fraction);
  EXPECT_EQ(s.guiding->combination, GuideCombination::Discard);
  EXPECT_EQ(s.guiding->roulette, GuideRoulette::Guided);
  EXPECT_EQ(s.guiding->spatial_filter, SpatialFilter::Stochastic);
  EXPECT_EQ(s.guiding->directional_filter, DirectionalFilter::Box);
  EXPECT_FLOAT_EQ(s.guiding->bsdf_fraction, 0.4f);
  EXPECT_DOUBLE_EQ(s.guiding->spatial_threshold, 4000);
  EXPECT_NEAR(s.guiding->directional_threshold, 0.02, 1e-7);
  EXPECT_EQ(s.guiding->max_bytes, size_t(64) << 20);
  EXPECT_EQ(r.scene->sampler.sample_count, 64);  // the budget, over the sampler's 4
  EXPECT_TRUE(r.unsupported.empty());
}

TEST(GuidedPathLoader, ThePluginsDefaultsAndItsNotes) {
  LoadResult r = load(kSpp);
  ASSERT_TRUE(r.scene->integrator.guiding.has_value());
  EXPECT_FALSE(r.scene->integrator.guiding->learn_bsdf_fraction);  // bsdfSamplingFractionLoss "none"
  EXPECT_FLOAT_EQ(r.scene->integrator.guiding->bsdf_fraction, 0.5f);
  EXPECT_EQ(r.scene->integrator.guiding->max_bytes, size_t(256) << 20);
  // The plugin's own, not Tessera's defaults (GuidingSettings).
  EXPECT_DOUBLE_EQ(r.scene->integrator.guiding->spatial_threshold, 12000);
  EXPECT_EQ(r.scene->integrator.guiding->spatial_filter, SpatialFilter::Nearest);
  EXPECT_EQ(r.scene->integrator.guiding->directional_filter, DirectionalFilter::Nearest);
  std::string notes;
  for (const auto& m : r.messages) notes += m.text + "\n";
  EXPECT_NE(notes.find("sampleCombination"), std::string::npos) << notes;
  EXPECT_NE(notes.find("next-event estimation"), std::string::npos) << notes;  // nee "never"
  EXPECT_EQ(r.scene->integrator.guiding->combination, GuidingSettings{}.combination);
  EXPECT_EQ(r.scene->sampler.sample_count, 64);
}

TEST(GuidedPathLoader, TimeBudgetsAreRefused) {
  const std::string seconds = error_of("<string name=\"budgetType\" value=\"seconds\"/>\n");
  EXPECT_NE(seconds.find("guided.xml:3"), std::string::npos) << seconds;
  EXPECT_NE(seconds.find("machine"), std::string::npos) << seconds;
  const std::string fallback = error_of("");
  EXPECT_NE(fallback.find("300 seconds"), std::string::npos) << fallback;
  EXPECT_NE(fallback.find("guided.xml:2"), std::string::npos) << fallback;
}

TEST(GuidedPathLoader, OutOfRangeValuesNameTheLineAndParameter) {
  const std::pair<std::string, std::string> cases[] = {
      {"<float name=\"dTreeThreshold\" value=\"2\"/>\n", "d_tree_threshold"},
      {"<float name=\"bsdfSamplingFraction\" value=\"0\"/>\n", "bsdf_sampling_fraction"},
      {"<integer name=\"sTreeThreshold\" value=\"-5\"/>\n", "s_tree_threshold"},
      {"<integer name=\"sdTreeMaxMemory\" value=\"0\"/>\n", "sd_tree_max_memory"},
      {"<string name=\"spatialFilter\" value=\"gaussian\"/>\n", "spatial_filter"},
      {"<float name=\"budget\" value=\"0\"/>\n", "budget"},
      {"<string name=\"roulette\" value=\"adjoint\"/>\n", "roulette"},
  };
  for (const auto& [param, name] : cases) {
    const std::string e = error_of(kSpp + param);
    EXPECT_NE(e.find("guided.xml:5"), std::string::npos) << e;
    EXPECT_NE(e.find("'" + name + "'"), std::string::npos) << e;
  }
}

TEST(GuidedPathLoader, UnimplementedOptionsAreUnsupported) {
  for (const std::string& param : {std::string("<string name=\"spatialFilter\" value=\"box\"/>\n"),
                                   std::string("<string name=\"sampleCombination\" value=\"automatic\"/>\n"),
                                   std::string("<string name=\"bsdfSamplingFractionLoss\" value=\"var\"/>\n")}) {
    EXPECT_THROW((void)load(kSpp + param), UnsupportedError) << param;
    LoadResult r = load(kSpp + param, /*allow_unsupported=*/true);
    ASSERT_EQ(r.unsupported.size(), 1u) << param;
    EXPECT_EQ(r.unsupported[0].loc.line, 5) << param;
    EXPECT_TRUE(r.scene->integrator.guiding.has_value());
  }
}

TEST(GuidedPathLoader, InverseVarianceCombinesTheLastIterations) {
  LoadResult r = load(kSpp + "<string name=\"sampleCombination\" value=\"inversevar\"/>\n");
  EXPECT_EQ(r.scene->integrator.guiding->combination, GuideCombination::InverseVariance);
  EXPECT_TRUE(r.unsupported.empty());
}

TEST(GuidedPathLoader, OtherIntegratorsAskForNoGuiding) {
  LoadResult r = load_scene(parse_scene_string("<scene version=\"3.0.0\"><integrator type=\"path\"/></scene>", "mem/p.xml"),
                            LoadOptions{});
  EXPECT_FALSE(r.scene->integrator.guiding.has_value());
}

}  // namespace
}  // namespace tessera
