// Confinement of a scene's files to its bundle (ParseOptions/LoadOptions::root_dir): a scene that
// arrives over the network must not make the coordinator read `../x`, `/abs/x` or a symlink out of
// the bundle, through any of the parameters that name files; an unconfined load keeps `../x`.
#include "tessera/farm/job_scene.h"
#include "tessera/image/image.h"
#include "tessera/scene/load_context.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

constexpr const char* kQuadObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
constexpr const char* kGreySpd = "# wavelength value\n400 0.5\n700 0.5\n";

/// A temp folder holding `bundle/` (the confinement root) and, beside it, files the scene must not
/// reach: outside.obj, outside.xml, wood.pfm, grey.spd and assets/a.obj.
struct Fixture {
  TempDir t;
  fs::path bundle;

  Fixture() : bundle(t.path / "bundle") {
    fs::create_directories(bundle);
    t.write("outside.obj", kQuadObj);
    t.write("assets/a.obj", kQuadObj);
    t.write("grey.spd", kGreySpd);
    t.write("outside.xml", "<scene version=\"3.0.0\"/>\n");
    write_image("wood.pfm");
  }
  std::string root() const { return bundle.string(); }
  void write_image(const std::string& rel) const {
    fs::create_directories((t.path / rel).parent_path());
    write_pfm((t.path / rel).string(), Image(4, 4, 3));  // an envmap needs at least 2x3 texels
  }
  /// bundle/scene.xml; the first line of `body` is line 2 of the file.
  std::string scene(const std::string& body) const {
    return t.write("bundle/scene.xml", "<scene version=\"3.0.0\">\n" + body + "\n</scene>\n");
  }
  ParseOptions confined() const {
    ParseOptions o;
    o.root_dir = root();
    return o;
  }
};

std::string obj_shape(const std::string& file) {
  return "<shape type=\"obj\"><string name=\"filename\" value=\"" + file + "\"/></shape>";
}

/// The SceneError of parsing (and loading) `xml` confined to `root`; fails when there is none.
SceneError error_of(const std::string& xml, const std::string& root) {
  try {
    ParseOptions po;
    po.root_dir = root;
    (void)load_scene(parse_scene_file(xml, po), LoadOptions{});
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "expected a SceneError";
  return SceneError("none");
}

void expect_outside(const SceneError& e, const std::string& file, int line, const std::string& name) {
  EXPECT_EQ(e.loc().file, file);
  EXPECT_EQ(e.loc().line, line);
  EXPECT_EQ(std::string(e.what()), file + ":" + std::to_string(line) + ": file '" + name +
                                       "' is outside the scene bundle");
}

TEST(Confinement, ObjMeshAboveTheBundleIsRefusedAtItsParameter) {
  Fixture f;
  const std::string xml = f.scene("  <bsdf type=\"diffuse\" id=\"m\"/>\n" + obj_shape("../outside.obj"));
  expect_outside(error_of(xml, f.root()), xml, 3, "../outside.obj");
}

TEST(Confinement, LoadOptionsRootAloneConfinesTheLoader) {
  Fixture f;
  const std::string xml = f.scene(obj_shape("../outside.obj"));
  LoadOptions lo;
  lo.root_dir = f.root();
  SceneDesc desc = parse_scene_file(xml);  // parsed unconfined: nothing in the XML is a file yet
  EXPECT_TRUE(desc.root_dir.empty());
  std::string msg = test::scene_error_of([&] { (void)load_scene(desc, lo); });
  EXPECT_EQ(msg, xml + ":2: file '../outside.obj' is outside the scene bundle");
}

TEST(Confinement, AbsolutePathIsRefusedWhetherOrNotItExists) {
  Fixture f;
  const std::string existing = (f.t.path / "outside.obj").string();
  std::string xml = f.scene(obj_shape(existing));
  expect_outside(error_of(xml, f.root()), xml, 2, existing);
  // Outside names are refused before any look-up: the message does not reveal what exists.
  xml = f.scene(obj_shape("/nonexistent-dir/x.obj"));
  expect_outside(error_of(xml, f.root()), xml, 2, "/nonexistent-dir/x.obj");
  xml = f.scene(obj_shape("../nonexistent.obj"));
  expect_outside(error_of(xml, f.root()), xml, 2, "../nonexistent.obj");
}

TEST(Confinement, SiblingFolderSharingTheNamePrefixIsOutside) {
  Fixture f;
  f.t.write("bundle2/a.obj", kQuadObj);  // "/tmp/x/bundle2" starts with "/tmp/x/bundle"
  const std::string xml = f.scene(obj_shape("../bundle2/a.obj"));
  expect_outside(error_of(xml, f.root()), xml, 2, "../bundle2/a.obj");
}

TEST(Confinement, IncludeAboveTheBundleIsRefused) {
  Fixture f;
  const std::string xml = f.scene("\n  <include filename=\"../outside.xml\"/>");
  expect_outside(error_of(xml, f.root()), xml, 3, "../outside.xml");
}

TEST(Confinement, SceneFileItselfMustBeInside) {
  Fixture f;
  const std::string xml = (f.t.path / "outside.xml").string();
  std::string msg = test::scene_error_of([&] { (void)parse_scene_file(xml, f.confined()); });
  EXPECT_EQ(msg, xml + ": file '" + xml + "' is outside the scene bundle");
}

TEST(Confinement, BitmapAndEnvmapOutsideAreRefused) {
  Fixture f;
  f.write_image("bundle/inside.pfm");
  std::string xml = f.scene(R"(<shape type="obj"><string name="filename" value="../bundle/./m.obj"/>
  <bsdf type="diffuse">
    <texture type="bitmap" name="reflectance">
      <string name="filename" value="../wood.pfm"/>
    </texture>
  </bsdf>
</shape>)");
  f.t.write("bundle/m.obj", kQuadObj);
  // The mesh name wanders out and back in, so it is inside; the texture is refused at its line.
  expect_outside(error_of(xml, f.root()), xml, 5, "../wood.pfm");

  xml = f.scene(R"(<emitter type="envmap">
  <string name="filename" value="../wood.pfm"/>
</emitter>)");
  expect_outside(error_of(xml, f.root()), xml, 3, "../wood.pfm");
  // The same emitter reading an image of the bundle loads.
  xml = f.scene(R"(<emitter type="envmap"><string name="filename" value="inside.pfm"/></emitter>)");
  ParseOptions po = f.confined();
  EXPECT_NO_THROW((void)load_scene(parse_scene_file(xml, po), LoadOptions{}));
}

TEST(Confinement, SpectrumFileOutsideIsRefused) {
  Fixture f;
  const std::string xml = f.scene(R"(<bsdf type="diffuse">
  <spectrum name="reflectance" filename="../grey.spd"/>
</bsdf>)");
  expect_outside(error_of(xml, f.root()), xml, 3, "../grey.spd");
  f.t.write("bundle/data/grey.spd", kGreySpd);
  f.scene(R"(<bsdf type="diffuse"><spectrum name="reflectance" filename="data/grey.spd"/></bsdf>)");
  SceneDesc d = parse_scene_file(xml, f.confined());
  EXPECT_EQ(d.spectrum_files.size(), 1u);
}

TEST(Confinement, SymlinksInsideThatPointOutsideAreRefused) {
  Fixture f;
  fs::create_symlink(f.t.path / "outside.obj", f.bundle / "link.obj");
  fs::create_directory_symlink(f.t.path / "assets", f.bundle / "meshes");
  fs::create_symlink(f.t.path / "outside.xml", f.bundle / "inc.xml");
  fs::create_symlink(f.t.path / "grey.spd", f.bundle / "grey.spd");

  std::string xml = f.scene(obj_shape("link.obj"));
  expect_outside(error_of(xml, f.root()), xml, 2, "link.obj");
  xml = f.scene(obj_shape("meshes/a.obj"));
  expect_outside(error_of(xml, f.root()), xml, 2, "meshes/a.obj");
  xml = f.scene(R"(<include filename="inc.xml"/>)");
  expect_outside(error_of(xml, f.root()), xml, 2, "inc.xml");
  xml = f.scene(R"(<bsdf type="diffuse"><spectrum name="reflectance" filename="grey.spd"/></bsdf>)");
  expect_outside(error_of(xml, f.root()), xml, 2, "grey.spd");

  // Unconfined, the same links are followed (a local scene may symlink its asset folders).
  xml = f.scene(obj_shape("meshes/a.obj"));
  EXPECT_EQ(load_scene(parse_scene_file(xml), LoadOptions{}).scene->num_triangles(), 2u);
}

TEST(Confinement, SymlinkBetweenFilesOfTheBundleIsAccepted) {
  Fixture f;
  f.t.write("bundle/real/a.obj", kQuadObj);
  fs::create_symlink(f.bundle / "real/a.obj", f.bundle / "alias.obj");
  const std::string xml = f.scene(obj_shape("alias.obj"));
  EXPECT_EQ(load_scene(parse_scene_file(xml, f.confined()), LoadOptions{}).scene->num_triangles(), 2u);
}

TEST(Confinement, FilesInSubfoldersOfTheBundleLoad) {
  Fixture f;
  f.t.write("bundle/meshes/a.obj", kQuadObj);
  f.t.write("bundle/data/grey.spd", kGreySpd);
  f.write_image("bundle/textures/wood.pfm");
  // An included file's names resolve against its own folder too: "../meshes/a.obj" from parts/
  // is inside, although the same name against the scene's folder is not.
  f.t.write("bundle/parts/shape.xml", R"(<scene version="3.0.0">
  <shape type="obj"><string name="filename" value="../meshes/a.obj"/><ref id="m"/></shape>
</scene>
)");
  const std::string xml = f.scene(R"(<bsdf type="diffuse" id="m">
  <texture type="bitmap" name="reflectance"><string name="filename" value="textures/wood.pfm"/></texture>
</bsdf>
<bsdf type="diffuse" id="grey"><spectrum name="reflectance" filename="data/grey.spd"/></bsdf>
<shape type="obj"><string name="filename" value="meshes/a.obj"/><ref id="grey"/></shape>
<include filename="parts/shape.xml"/>)");
  SceneDesc desc = parse_scene_file(xml, f.confined());
  EXPECT_EQ(desc.root_dir, f.root());
  LoadResult r = load_scene(desc, LoadOptions{});
  EXPECT_EQ(r.scene->num_triangles(), 4u);
  ASSERT_GE(r.files.size(), 2u);  // the mesh (however many spellings) and the texture
  for (const std::string& file : r.files) {
    const fs::path rel = fs::weakly_canonical(file).lexically_relative(fs::weakly_canonical(f.bundle));
    const std::string first = rel.empty() ? std::string() : rel.begin()->string();
    EXPECT_TRUE(first == "meshes" || first == "textures") << file;
  }
  EXPECT_EQ(desc.included_files.size(), 1u);
  EXPECT_EQ(desc.spectrum_files.size(), 1u);
}

TEST(Confinement, RelativeRootIsConfinedAlike) {
  Fixture f;
  f.t.write("bundle/meshes/a.obj", kQuadObj);
  const fs::path rel = fs::relative(f.bundle);  // to the working directory, whichever it is
  ASSERT_FALSE(rel.empty());
  std::string xml = f.scene(obj_shape("meshes/a.obj"));
  ParseOptions po;
  po.root_dir = rel.string();
  const std::string rel_xml = (rel / "scene.xml").string();
  EXPECT_EQ(load_scene(parse_scene_file(rel_xml, po), LoadOptions{}).scene->num_triangles(), 2u);
  f.scene(obj_shape("../outside.obj"));
  expect_outside(error_of(rel_xml, rel.string()), rel_xml, 2, "../outside.obj");
}

TEST(Confinement, UnconfinedLoadReadsAboveTheSceneFolder) {
  Fixture f;
  const std::string xml = f.scene(obj_shape("../outside.obj") + "\n" + obj_shape("../assets/a.obj"));
  SceneDesc desc = parse_scene_file(xml);
  EXPECT_TRUE(desc.root_dir.empty());
  LoadResult r = load_scene(desc, LoadOptions{});
  EXPECT_EQ(r.scene->num_triangles(), 4u);
}

TEST(Confinement, JobSceneIsConfinedToItsBundle) {
  Fixture f;
  f.t.write("bundle/scenes/meshes/a.obj", kQuadObj);
  // Inside the bundle, a scene in a subfolder may still reach up to its neighbours.
  f.t.write("bundle/scenes/s/scene.xml", "<scene version=\"3.0.0\">\n" + obj_shape("../meshes/a.obj") + "\n</scene>\n");
  LoadedJobScene ok = load_job_scene(f.root(), "scenes/s/scene.xml", JobSettings{});
  EXPECT_EQ(ok.loaded.scene->num_triangles(), 2u);
  EXPECT_EQ(ok.desc.root_dir, f.root());

  const std::string xml = f.scene(obj_shape("../outside.obj"));
  std::string msg = test::scene_error_of([&] { (void)load_job_scene(f.root(), "scene.xml", JobSettings{}); });
  EXPECT_EQ(msg, xml + ":2: file '../outside.obj' is outside the scene bundle");
  f.scene("<include filename=\"../outside.xml\"/>");
  msg = test::scene_error_of([&] { (void)load_job_scene(f.root(), "scene.xml", JobSettings{}); });
  EXPECT_EQ(msg, xml + ":2: file '../outside.xml' is outside the scene bundle");
}

}  // namespace
}  // namespace tessera
