// The `tessera` command in-process: render writes EXR (with its header attributes), PFM and PNG;
// -D reaches the scene; errors give exit code 1 or 2; a guided_path scene renders guided unless
// --guiding off; --adaptive changes the samples; compare reports errors against a reference.
#include "tessera/cli/commands.h"
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace tessera {
namespace {

namespace fs = std::filesystem;

int run(std::vector<std::string> args) {
  args.insert(args.begin(), "tessera");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return cli::main_entry(int(argv.size()), argv.data());
}

struct CliTest : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("tessera_cli_test_" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  std::string write_scene() const {
    // A grey diffuse plane under a constant sky whose radiance is a $default.
    std::ofstream(path("s.xml")) << R"(<scene version="3.0.0">
  <default name="sky" value="1"/>
  <sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="8"/></film>
  </sensor>
  <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <emitter type="constant"><rgb name="radiance" value="$sky"/></emitter>
</scene>)";
    return path("s.xml");
  }
};

TEST_F(CliTest, RenderWritesEveryFormatWithHeaderAttributes) {
  std::string scene = write_scene();
  ASSERT_EQ(run({"render", scene, "-o", path("a.exr"), "-o", path("a.pfm"), "-o", path("a.png"), "--seed", "7",
                 "-q"}),
            0);
  ImageAttributes attrs;
  Image exr = read_exr(path("a.exr"), &attrs);
  EXPECT_EQ(exr.width(), 16);
  EXPECT_EQ(exr.height(), 8);
  EXPECT_EQ(attrs["tessera_seed"], "7");
  EXPECT_EQ(attrs["tessera_spp"], "4");
  EXPECT_EQ(attrs["tessera_scene"], scene);
  EXPECT_FALSE(attrs["tessera_version"].empty());
  Image pfm = read_pfm(path("a.pfm"));
  EXPECT_EQ(rel_mse(pfm, exr), 0.0);
  EXPECT_TRUE(fs::exists(path("a.png")));
  // A diffuse plane of albedo 0.5 under a uniform sky of 1 reflects 0.5 (512 samples: ~5 sigma).
  EXPECT_NEAR(channel_means(exr)[0], 0.5, 0.1);
}

TEST_F(CliTest, DefinesReachTheSceneAndOverridesApply) {
  std::string scene = write_scene();
  auto render_with = [&](const std::string& out, const std::string& define) {
    return run({"render", scene, "-o", path(out), "-D", define, "--spp", "2", "--width", "4", "--height", "4", "-q"});
  };
  ASSERT_EQ(render_with("one.exr", "sky=1"), 0);
  ASSERT_EQ(render_with("two.exr", "sky=2"), 0);
  ImageAttributes attrs;
  Image one = read_exr(path("one.exr"));
  Image two = read_exr(path("two.exr"), &attrs);
  EXPECT_EQ(two.width(), 4);
  EXPECT_EQ(attrs["tessera_spp"], "2");
  // Same samples, twice the sky: every pixel exactly doubles.
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(two.at(x, y, 0), 2.f * one.at(x, y, 0));
  EXPECT_GT(channel_means(one)[0], 0.0);
}

TEST_F(CliTest, BadInputGivesAnErrorExitCode) {
  std::string scene = write_scene();
  EXPECT_EQ(run({"render", scene, "-o", path("x.bmp")}), 2);                    // unknown output format
  EXPECT_EQ(run({"render", scene, "-o", path("x.exr"), "-D", "novalue"}), 2);   // malformed -D
  EXPECT_EQ(run({"render", path("missing.xml"), "-o", path("x.exr")}), 1);      // missing scene
  EXPECT_NE(run({"render", scene, "-o", path("x.exr"), "--integrator", "bpdt"}), 0);  // not an integrator
  EXPECT_FALSE(fs::exists(path("x.exr")));
}

TEST_F(CliTest, EveryIntegratorTheLoaderKnowsIsAccepted) {
  std::string scene = write_scene();
  for (const char* integrator : {"path", "volpath", "direct", "bdpt", "ptracer"}) {
    const std::string out = path(std::string(integrator) + ".exr");
    EXPECT_EQ(run({"render", scene, "-o", out, "--integrator", integrator, "-q"}), 0) << integrator;
    EXPECT_TRUE(fs::exists(out)) << integrator;
  }
}

TEST_F(CliTest, GuidingFollowsTheScenesIntegratorUnlessToldAndAdaptiveIsAFlag) {
  std::string scene = write_scene();
  std::string xml;
  {
    std::ifstream in(scene);
    xml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string guided_xml = std::string(xml).insert(xml.find("<sensor"), R"(<integrator type="guided_path">
    <string name="budgetType" value="spp"/><float name="budget" value="32"/>
    <string name="sampleCombination" value="discard"/></integrator>
  )");
  std::ofstream(path("g.xml")) << guided_xml;
  const auto render_to = [&](const std::string& file, const std::string& out, std::vector<std::string> flags) {
    std::vector<std::string> args = {"render", file, "-o", path(out), "--seed", "3", "-q"};
    args.insert(args.end(), flags.begin(), flags.end());
    return run(args);
  };
  ASSERT_EQ(render_to(path("g.xml"), "guided.exr", {}), 0);
  ASSERT_EQ(render_to(path("g.xml"), "off.exr", {"--guiding", "off"}), 0);
  ASSERT_EQ(render_to(scene, "plain.exr", {"--spp", "32"}), 0);
  ASSERT_EQ(render_to(scene, "adaptive.exr", {"--spp", "32", "--adaptive", "on"}), 0);
  const Image plain = read_exr(path("plain.exr"));
  EXPECT_EQ(rel_mse(read_exr(path("off.exr")), plain), 0.0);  // guided_path without guiding is path
  EXPECT_GT(rel_mse(read_exr(path("guided.exr")), plain), 0.0);
  EXPECT_GT(rel_mse(read_exr(path("adaptive.exr")), plain), 0.0);
  EXPECT_NE(render_to(scene, "x.exr", {"--adaptive", "maybe"}), 0);
}

TEST_F(CliTest, CompareReportsAgainstAReference) {
  std::string scene = write_scene();
  ASSERT_EQ(run({"render", scene, "-o", path("c.exr"), "-q"}), 0);
  EXPECT_EQ(run({"compare", path("c.exr"), path("c.exr")}), 0);
  Image other(4, 4, 3);
  write_exr(path("small.exr"), other);
  EXPECT_EQ(run({"compare", path("c.exr"), path("small.exr")}), 1);  // size mismatch
}

}  // namespace
}  // namespace tessera
