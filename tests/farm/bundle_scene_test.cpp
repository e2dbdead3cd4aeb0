// Bundling real scenes: the files a scene references (scene_files), their common root
// (plan_bundle), packing, and the round trip pack -> inspect -> unpack -> load.
#include "tessera/farm/bundle.h"
#include "tessera/farm/job_scene.h"

#include "tessera/image/image.h"
#include "tessera/scene/load_context.h"

#include "farm/archive_builder.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::ArchiveBuilder;
using test::TempDir;

struct Loaded {
  SceneDesc desc;
  LoadResult result;
};

Loaded load_file(const std::string& path) {
  Loaded l;
  l.desc = parse_scene_file(path);
  LoadOptions opt;
  opt.allow_unsupported = true;  // the bundle round trip is about files, not plugin coverage
  l.result = load_scene(l.desc, opt);
  return l;
}

/// Bundles `scene_xml` as `tessera submit` would, unpacks it into `dest`, loads it from there, and
/// checks it matches the original. Returns the bundle's file list.
std::vector<std::string> round_trip(const std::string& scene_xml, const fs::path& dest) {
  Loaded original = load_file(scene_xml);
  BundlePlan plan = plan_bundle(scene_xml, scene_files(original.desc, original.result));
  const std::string bytes = pack_bundle(plan.root_dir, plan.files);
  BundleResult listed = inspect_bundle(bytes);
  EXPECT_TRUE(listed.ok()) << listed.error;
  EXPECT_EQ(listed.files.size(), plan.files.size());
  std::string err;
  const std::string xml = find_scene_xml(listed.files, plan.files[0], err);
  EXPECT_EQ(xml, plan.files[0]) << err;

  BundleResult unpacked = unpack_bundle(bytes, dest.string());
  EXPECT_TRUE(unpacked.ok()) << unpacked.error;
  Loaded copy = load_file((dest / xml).string());
  EXPECT_EQ(copy.result.scene->num_triangles(), original.result.scene->num_triangles());
  EXPECT_EQ(copy.result.scene->shapes.size(), original.result.scene->shapes.size());
  EXPECT_EQ(copy.result.scene->textures.size(), original.result.scene->textures.size());
  EXPECT_EQ(copy.result.files.size(), original.result.files.size());
  return plan.files;
}

TEST(BundleScene, CornellBoxRoundTrip) {
  const std::string path = test::shared_path("scenes/cornell-box/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  TempDir t;
  std::vector<std::string> files = round_trip(path, t.path / "bundle");
  EXPECT_EQ(files, std::vector<std::string>{"scene.xml"});  // not LICENSE.txt or PROVENANCE.md
}

TEST(BundleScene, SceneWithMeshesAndTexturesInSubfolders) {
  const std::string path = test::shared_path("scenes/staircase2/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  TempDir t;
  std::vector<std::string> files = round_trip(path, t.path / "bundle");
  ASSERT_GT(files.size(), 3u);
  EXPECT_EQ(files[0], "scene.xml");
  EXPECT_TRUE(std::is_sorted(files.begin() + 1, files.end()));
  EXPECT_TRUE(std::count(files.begin(), files.end(), "textures/Tiles.jpg"));
  EXPECT_TRUE(std::count(files.begin(), files.end(), "models/Mesh008.obj"));
  EXPECT_FALSE(std::count(files.begin(), files.end(), "LICENSE.txt"));
}

constexpr const char* kQuadObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";

void write_pfm_texture(const fs::path& p) {
  fs::create_directories(p.parent_path());
  Image im(2, 2, 3);
  write_pfm(p.string(), im);
}

/// A scene in project/scenes/s/ that reaches up for its assets: ../meshes and ../../assets.
std::string write_upward_scene(const TempDir& t) {
  write_pfm_texture(t.path / "project/assets/wood.pfm");
  t.write("project/scenes/meshes/quad.obj", kQuadObj);
  t.write("project/scenes/s/unrelated.txt", "not referenced");
  return t.write("project/scenes/s/scene.xml", R"(<scene version="3.0.0">
  <bsdf type="diffuse" id="m">
    <texture type="bitmap" name="reflectance"><string name="filename" value="../../assets/wood.pfm"/></texture>
  </bsdf>
  <shape type="obj"><string name="filename" value="../meshes/quad.obj"/><ref id="m"/></shape>
  <shape type="obj"><string name="filename" value="../meshes/./quad.obj"/><ref id="m"/></shape>
</scene>
)");
}

TEST(BundleScene, ReferencesOutsideTheSceneFolder) {
  TempDir t;
  const std::string xml = write_upward_scene(t);
  Loaded l = load_file(xml);
  BundlePlan plan = plan_bundle(xml, scene_files(l.desc, l.result));
  EXPECT_EQ(fs::path(plan.root_dir), (t.path / "project").lexically_normal());
  EXPECT_EQ(plan.files, (std::vector<std::string>{"scenes/s/scene.xml", "assets/wood.pfm", "scenes/meshes/quad.obj"}));
  TempDir out;
  round_trip(xml, out.path / "b");
  EXPECT_TRUE(fs::exists(out.path / "b/assets/wood.pfm"));
  EXPECT_FALSE(fs::exists(out.path / "b/scenes/s/unrelated.txt"));
}

TEST(BundleScene, ZipOfTheSceneLoads) {
  TempDir t;
  const std::string xml = write_upward_scene(t);
  Loaded l = load_file(xml);
  BundlePlan plan = plan_bundle(xml, scene_files(l.desc, l.result));
  ArchiveBuilder zip(ArchiveBuilder::Format::Zip);
  for (const std::string& f : plan.files) {
    std::ifstream in(fs::path(plan.root_dir) / f, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    zip.file(f, ss.str());
  }
  TempDir out;
  BundleResult r = unpack_bundle(zip.finish(), (out.path / "z").string());
  ASSERT_TRUE(r.ok()) << r.error;
  Loaded copy = load_file((out.path / "z/scenes/s/scene.xml").string());
  EXPECT_EQ(copy.result.scene->num_triangles(), 4u);
}

TEST(BundleScene, SymlinkedAssetFolderKeepsTheSceneLayout) {
  TempDir t;
  write_pfm_texture(t.path / "library/wood.pfm");
  fs::create_directories(t.path / "scene");
  fs::create_directory_symlink(t.path / "library", t.path / "scene/textures");
  t.write("scene/quad.obj", kQuadObj);
  const std::string xml = t.write("scene/scene.xml", R"(<scene version="3.0.0">
  <shape type="obj"><string name="filename" value="quad.obj"/>
    <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="textures/wood.pfm"/></texture></bsdf>
  </shape>
</scene>
)");
  Loaded l = load_file(xml);
  BundlePlan plan = plan_bundle(xml, scene_files(l.desc, l.result));
  EXPECT_EQ(plan.files, (std::vector<std::string>{"scene.xml", "quad.obj", "textures/wood.pfm"}));
  TempDir out;
  round_trip(xml, out.path / "b");
}

TEST(BundleScene, SceneFilesListIncludesAndSpectrumFiles) {
  TempDir t;
  t.write("parts/quad.obj", kQuadObj);
  t.write("data/grey.spd", "# wavelength value\n400 0.5\n700 0.5\n");
  const std::string inc = t.write("parts/materials.xml", R"(<scene version="3.0.0">
  <bsdf type="diffuse" id="m"><spectrum name="reflectance" filename="data/grey.spd"/></bsdf>
</scene>
)");
  const std::string xml = t.write("scene.xml", R"(<scene version="3.0.0">
  <include filename="parts/materials.xml"/>
  <shape type="obj"><string name="filename" value="parts/quad.obj"/><ref id="m"/></shape>
</scene>
)");
  Loaded l = load_file(xml);
  ASSERT_EQ(l.desc.included_files.size(), 1u);
  EXPECT_TRUE(fs::equivalent(l.desc.included_files[0], inc));
  ASSERT_EQ(l.desc.spectrum_files.size(), 1u);
  EXPECT_TRUE(fs::equivalent(l.desc.spectrum_files[0], t.path / "data/grey.spd"));
  ASSERT_EQ(l.result.files.size(), 1u);
  EXPECT_TRUE(fs::equivalent(l.result.files[0], t.path / "parts/quad.obj"));

  std::vector<std::string> files = scene_files(l.desc, l.result);
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(files[0], xml);
  EXPECT_EQ(files[1], l.desc.included_files[0]);
  BundlePlan plan = plan_bundle(xml, files);
  EXPECT_EQ(plan.files,
            (std::vector<std::string>{"scene.xml", "data/grey.spd", "parts/materials.xml", "parts/quad.obj"}));
  TempDir out;
  round_trip(xml, out.path / "b");
}

TEST(BundleScene, LoaderFilesAreDeduplicatedInFirstUseOrder) {
  TempDir t;
  t.write("b.obj", kQuadObj);
  t.write("a.obj", kQuadObj);
  const std::string xml = t.write("scene.xml", R"(<scene version="3.0.0">
  <shape type="obj"><string name="filename" value="b.obj"/></shape>
  <shape type="obj"><string name="filename" value="a.obj"/></shape>
  <shape type="obj"><string name="filename" value="b.obj"/><boolean name="face_normals" value="true"/></shape>
</scene>
)");
  Loaded l = load_file(xml);
  ASSERT_EQ(l.result.files.size(), 2u);
  EXPECT_EQ(fs::path(l.result.files[0]).filename(), "b.obj");
  EXPECT_EQ(fs::path(l.result.files[1]).filename(), "a.obj");
}

TEST(BundlePack, IsDeterministic) {
  TempDir t;
  t.write("scene.xml", "<scene/>");
  t.write("sub/m.obj", kQuadObj);
  const std::string a = pack_bundle(t.path.string(), {"scene.xml", "sub/m.obj"});
  fs::last_write_time(t.path / "sub/m.obj", fs::file_time_type::clock::now() - std::chrono::hours(50));
  const std::string b = pack_bundle(t.path.string(), {"scene.xml", "sub/m.obj"});
  EXPECT_EQ(a, b);
  ASSERT_GT(a.size(), 10u);
  EXPECT_EQ(a.substr(4, 4), std::string(4, '\0'));  // no gzip timestamp
}

TEST(BundlePack, MissingOrEscapingFileThrows) {
  TempDir t;
  t.write("scene.xml", "<scene/>");
  EXPECT_THROW((void)pack_bundle(t.path.string(), {"scene.xml", "nope.obj"}), std::runtime_error);
  EXPECT_THROW((void)pack_bundle(t.path.string(), {"../scene.xml"}), std::runtime_error);
  EXPECT_THROW((void)pack_bundle(t.path.string(), {(t.path / "scene.xml").string()}), std::runtime_error);
  fs::create_directory(t.path / "dir");
  EXPECT_THROW((void)pack_bundle(t.path.string(), {"dir"}), std::runtime_error);
}

TEST(BundlePack, NonAsciiNamesSurvive) {
  TempDir t;
  t.write("textures/caf\xc3\xa9 1.png", "x");
  BundleResult r = inspect_bundle(pack_bundle(t.path.string(), {"textures/caf\xc3\xa9 1.png"}));
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.files.size(), 1u);
  EXPECT_EQ(r.files[0].path, "textures/caf\xc3\xa9 1.png");
}

TEST(BundlePlan, RootIsTheDeepestCommonFolder) {
  BundlePlan p = plan_bundle("/a/b/c/scene.xml", {"/a/b/c/scene.xml", "/a/b/c/m/x.obj", "/a/b/t/y.png", "/a/b/c/m/x.obj"});
  EXPECT_EQ(p.root_dir, "/a/b");
  EXPECT_EQ(p.files, (std::vector<std::string>{"c/scene.xml", "c/m/x.obj", "t/y.png"}));
  BundlePlan q = plan_bundle("/a/b/c/scene.xml", {"/a/b/c/../../z.png"});
  EXPECT_EQ(q.root_dir, "/a");
  EXPECT_EQ(q.files, (std::vector<std::string>{"b/c/scene.xml", "z.png"}));
  BundlePlan alone = plan_bundle("/s/scene.xml", {});
  EXPECT_EQ(alone.root_dir, "/s");
  EXPECT_EQ(alone.files, std::vector<std::string>{"scene.xml"});
}

TEST(JobPlan, GuidingFollowsTheJobElseTheScene) {
  TempDir t;
  std::ofstream(t.path / "scene.xml") << R"(<scene version="0.6.0">
  <integrator type="guided_path"><string name="budgetType" value="spp"/><float name="budget" value="16"/>
    <string name="sampleCombination" value="discard"/></integrator>
  <shape type="sphere"/>
</scene>)";
  JobSettings settings;
  auto plan = [&] {
    return make_job_plan(t.path.string(), "scene.xml", settings, load_job_scene(t.path.string(), "scene.xml", settings));
  };
  const JobPlan guided = plan();
  ASSERT_TRUE(guided.guide) << "the scene's guided_path integrator asks for guiding";
  EXPECT_EQ(guided.guide->settings.bsdf_fraction, 0.5f);
  JobPlan back;
  std::string error;
  ASSERT_TRUE(job_plan_from_json(to_json(guided), back, error)) << error;
  EXPECT_EQ(to_json(back), to_json(guided));
  settings.guiding = false;
  EXPECT_FALSE(plan().guide);
  settings.guiding.reset();
  settings.integrator = "direct";  // nothing to guide
  EXPECT_FALSE(plan().guide);
  settings.integrator = "path";
  settings.guiding = true;  // asked for on any scene
  EXPECT_TRUE(plan().guide);
}

// A scene file whose integrator is sppm is planned as `tessera render` runs it: a photon pass
// before each gather, and what makes its photon maps, kept with the plan (and through its JSON).
// Settings only the path tracer has are refused, naming what to do instead.
TEST(JobPlan, AnSppmScenePlansPhotonPassesAndItsMaps) {
  TempDir t;
  std::ofstream(t.path / "scene.xml") << R"(<scene version="0.6.0">
  <integrator type="sppm"><integer name="photonCount" value="1000"/><float name="initialRadius" value="0.25"/>
    <float name="alpha" value="0.6"/></integrator>
  <shape type="sphere"/>
  <sensor type="perspective"><sampler type="independent"><integer name="sampleCount" value="3"/></sampler>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film></sensor>
</scene>)";
  JobSettings settings;
  auto plan = [&] {
    return make_job_plan(t.path.string(), "scene.xml", settings, load_job_scene(t.path.string(), "scene.xml", settings));
  };
  const JobPlan p = plan();
  ASSERT_TRUE(p.points);
  EXPECT_EQ(p.points->type, IntegratorType::Sppm);
  EXPECT_EQ(p.points->radius(5), 0.25f);
  EXPECT_TRUE(p.program.passes == photon_program(3, 1000).passes);
  JobPlan back;
  std::string error;
  ASSERT_TRUE(job_plan_from_json(to_json(p), back, error)) << error;
  EXPECT_TRUE(back.points == p.points);
  EXPECT_TRUE(back.program.passes == p.program.passes);
  settings.target_error = 0.01;
  try {
    (void)plan();
    ADD_FAILURE() << "planned with a target error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a target error needs the path tracer"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera
