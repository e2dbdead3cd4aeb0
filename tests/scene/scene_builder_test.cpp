// Scene builder: integrator/sensor/film/sampler settings, shapes in world space, instancing, the
// mesh cache, and the all-at-once report of unsupported plugins and parameters.
// Uses the diffuse/twosided BSDFs, the rectangle/cube/sphere/obj shapes and the point/area lights.
#include "tessera/scene/load_context.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

using test::scene_error_of;

SceneDesc desc_of(const std::string& body, const std::string& version = "3.0.0",
                  const std::string& path = "mem/scene.xml") {
  return parse_scene_string("<scene version=\"" + version + "\">\n" + body + "\n</scene>\n", path);
}

LoadResult load(const std::string& body, LoadOptions opt = {}, const std::string& version = "3.0.0") {
  return load_scene(desc_of(body, version), opt);
}

const TriangleMeshShape& mesh_shape(const Scene& s, size_t i) {
  EXPECT_EQ(s.shapes.at(i)->kind(), Shape::Kind::Mesh);
  return static_cast<const TriangleMeshShape&>(*s.shapes.at(i));
}

Vec3 winding_normal(const MeshData& m, size_t tri) {
  Vec3 p0 = m.positions[m.indices[3 * tri]], p1 = m.positions[m.indices[3 * tri + 1]],
       p2 = m.positions[m.indices[3 * tri + 2]];
  return normalize(cross(p1 - p0, p2 - p0));
}

/// Full horizontal field of view of a camera with identity to_world, measured from its rays.
float measured_fov_x(const Camera& cam, int height) {
  Ray r = cam.generate_ray(Vec2(0.f, 0.5f * float(height)), Vec2(0.5f, 0.5f));
  return 2.f * std::atan2(std::abs(r.d.x), r.d.z) * 180.f / kPi;
}

const char* kCamera = R"(<sensor type="perspective">
  <float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/></film>
</sensor>)";

TEST(SceneBuilder, CornellBoxLoadsWithNothingUnsupported) {
  std::string path = test::shared_path("scenes/cornell-box/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  LoadResult r = load_scene(parse_scene_file(path), LoadOptions{});
  const Scene& s = *r.scene;
  EXPECT_TRUE(r.unsupported.empty());
  EXPECT_EQ(s.shapes.size(), 8u);
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.integrator.type, IntegratorType::Path);
  EXPECT_EQ(s.integrator.max_depth, 65);
  EXPECT_TRUE(s.integrator.strict_normals);
  EXPECT_EQ(s.film.width, 1024);
  EXPECT_EQ(s.film.height, 1024);
  EXPECT_TRUE(s.film.ldr);
  EXPECT_FLOAT_EQ(s.film.gamma, 2.2f);
  ASSERT_NE(s.film.filter, nullptr);
  EXPECT_EQ(s.film.filter->name(), "tent");
  EXPECT_EQ(s.sampler.type, SamplerType::Sobol);
  EXPECT_EQ(s.sampler.sample_count, 64);
  ASSERT_NE(s.camera, nullptr);
  for (const auto& shape : s.shapes) EXPECT_NE(shape->bsdf, nullptr);
  // The image-neutral film switches get one note each, not an error.
  bool banner_note = false;
  for (const auto& m : r.messages)
    banner_note |= m.level == LoadMessage::Level::Note && m.text.find("'banner'") != std::string::npos;
  EXPECT_TRUE(banner_note);
}

TEST(SceneBuilder, OverridesFromOptions) {
  std::string body = std::string(kCamera) + R"(
<integrator type="path"><integer name="max_depth" value="3"/></integrator>
<shape type="sphere"/>)";
  LoadOptions opt;
  opt.width = 40;
  opt.height = 20;
  opt.spp = 7;
  opt.integrator = "direct";
  LoadResult r = load(body, opt);
  EXPECT_EQ(r.scene->film.width, 40);
  EXPECT_EQ(r.scene->film.height, 20);
  EXPECT_EQ(r.scene->sampler.sample_count, 7);
  EXPECT_EQ(r.scene->integrator.type, IntegratorType::Direct);
  EXPECT_TRUE(r.unsupported.empty());  // the replaced integrator's max_depth is not an error
  opt.integrator = "bdpt";
  EXPECT_EQ(load(body, opt).scene->integrator.type, IntegratorType::Bdpt);
  opt.integrator = "bpdt";
  const std::string e = scene_error_of([&] { load(body, opt); });
  EXPECT_NE(e.find("unknown integrator 'bpdt' (use path, volpath, direct, bdpt, ptracer, sppm or vcm)"), std::string::npos) << e;
}

TEST(SceneBuilder, DefaultIntegratorDependsOnVersion) {
  std::string body = std::string(kCamera) + "<shape type=\"sphere\"/>";
  EXPECT_EQ(load(body, {}, "0.6.0").scene->integrator.type, IntegratorType::Direct);
  EXPECT_EQ(load(body, {}, "3.0.0").scene->integrator.type, IntegratorType::Path);
  auto r = load(R"(<integrator type="direct"><integer name="shadingSamples" value="3"/>
  <integer name="bsdfSamples" value="2"/></integrator>)" + body, {}, "0.6.0");
  EXPECT_EQ(r.scene->integrator.emitter_samples, 3);
  EXPECT_EQ(r.scene->integrator.bsdf_samples, 2);
}

TEST(SceneBuilder, FilmFilterAndSamplerDefaults) {
  LoadResult r = load("<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/></sensor><shape type=\"sphere\"/>");
  EXPECT_EQ(r.scene->film.width, 768);
  EXPECT_EQ(r.scene->film.height, 576);
  EXPECT_EQ(r.scene->film.filter->name(), "gaussian");
  EXPECT_FLOAT_EQ(r.scene->film.filter->radius(), 2.f);  // 4 standard deviations of 0.5
  EXPECT_EQ(r.scene->sampler.type, SamplerType::Independent);
  EXPECT_EQ(r.scene->sampler.sample_count, 4);

  r = load(R"(<sensor type="perspective"><float name="fov" value="30"/>
  <sampler type="ldsampler"><integer name="sample_count" value="16"/></sampler>
  <film type="ldrfilm"><integer name="width" value="100"/><integer name="height" value="50"/>
    <integer name="crop_offset_x" value="10"/><integer name="crop_width" value="20"/>
    <float name="exposure" value="1"/>
    <rfilter type="box"><float name="radius" value="0.75"/></rfilter></film>
</sensor><shape type="sphere"/>)");
  const FilmSettings& f = r.scene->film;
  EXPECT_EQ(f.crop_x, 10);
  EXPECT_EQ(f.crop_w(), 20);
  EXPECT_EQ(f.crop_h(), 50);
  EXPECT_TRUE(f.ldr);
  EXPECT_FLOAT_EQ(f.gamma, -1.f);
  EXPECT_FLOAT_EQ(f.exposure, 1.f);
  EXPECT_EQ(f.filter->name(), "box");
  EXPECT_FLOAT_EQ(f.filter->radius(), 0.75f);
  EXPECT_EQ(r.scene->sampler.type, SamplerType::Sobol);
  EXPECT_EQ(r.scene->sampler.sample_count, 16);
}

TEST(SceneBuilder, FieldOfViewAxes) {
  struct Case {
    const char* params;
    float expected_x;
  };
  // Film 32x16 (aspect 2).
  const float t40 = std::tan(20.f * kPi / 180.f);
  const Case cases[] = {
      {"<float name=\"fov\" value=\"40\"/>", 40.f},
      {"<float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"y\"/>",
       2.f * std::atan(2.f * t40) * 180.f / kPi},
      {"<float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"smaller\"/>",
       2.f * std::atan(2.f * t40) * 180.f / kPi},
      {"<float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"larger\"/>", 40.f},
      {"<float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"diagonal\"/>",
       2.f * std::atan(t40 / std::sqrt(1.25f)) * 180.f / kPi},
      {"<string name=\"focal_length\" value=\"50mm\"/>",
       2.f * std::atan(std::sqrt(36.f * 36.f + 24.f * 24.f) / 100.f / std::sqrt(1.25f)) * 180.f / kPi},
  };
  for (const Case& c : cases) {
    LoadResult r = load(std::string("<sensor type=\"perspective\">") + c.params +
                        "<film type=\"hdrfilm\"><integer name=\"width\" value=\"32\"/>"
                        "<integer name=\"height\" value=\"16\"/></film></sensor><shape type=\"sphere\"/>");
    EXPECT_NEAR(measured_fov_x(*r.scene->camera, 16), c.expected_x, 1e-3f) << c.params;
  }
  EXPECT_NE(scene_error_of([] { load("<sensor type=\"perspective\"><float name=\"fov\" value=\"180\"/></sensor>"); })
                .find("mem/scene.xml:2"),
            std::string::npos);
}

TEST(SceneBuilder, ShapesAreInWorldSpaceWithMitsubaOrientation) {
  std::string body = std::string(kCamera) + R"(
<shape type="rectangle"><transform name="to_world"><translate z="5"/></transform></shape>
<shape type="rectangle"><transform name="to_world"><scale x="-1"/><translate z="5"/></transform></shape>
<shape type="cube"><transform name="to_world"><scale x="-1"/></transform></shape>)";
  LoadResult r = load(body);
  ASSERT_EQ(r.scene->shapes.size(), 3u);
  const MeshData& a = mesh_shape(*r.scene, 0).mesh();
  for (Vec3 p : a.positions) EXPECT_FLOAT_EQ(p.z, 5.f);
  EXPECT_NEAR(winding_normal(a, 0).z, 1.f, 1e-6f);
  // Mirrored rectangle: Mitsuba's normal is to_world applied to +z as a normal, still +z.
  const MeshData& b = mesh_shape(*r.scene, 1).mesh();
  EXPECT_NEAR(winding_normal(b, 0).z, 1.f, 1e-6f);
  EXPECT_NEAR(winding_normal(b, 1).z, 1.f, 1e-6f);
  // A mirrored mesh keeps its winding (it turns inside out, as in Mitsuba); normals still unit.
  const MeshData& c = mesh_shape(*r.scene, 2).mesh();
  for (Vec3 n : c.normals) EXPECT_NEAR(length(n), 1.f, 1e-6f);
  for (const auto& s : r.scene->shapes) EXPECT_NE(s->bsdf, nullptr);  // default diffuse
}

TEST(SceneBuilder, SpheresTakeUniformScaleAndTranslation) {
  std::string body = std::string(kCamera) + R"(
<shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/>
  <transform name="to_world"><scale value="2"/><translate y="3"/></transform></shape>
<shape type="sphere"><transform name="to_world"><scale x="1" y="2" z="1"/></transform></shape>)";
  std::string msg;
  try {
    load(body);
  } catch (const UnsupportedError& e) {
    ASSERT_EQ(e.items().size(), 1u);
    EXPECT_EQ(e.items()[0].loc.line, 8);
    msg = e.what();
  }
  EXPECT_NE(msg.find("non-uniform"), std::string::npos) << msg;
  LoadOptions allow;
  allow.allow_unsupported = true;
  LoadResult r = load(body, allow);
  ASSERT_EQ(r.scene->shapes.size(), 2u);
  const auto& s = static_cast<const SphereShape&>(*r.scene->shapes[0]);
  EXPECT_NEAR(s.center().x, 2.f, 1e-6f);
  EXPECT_NEAR(s.center().y, 3.f, 1e-6f);
  EXPECT_NEAR(s.radius(), 1.f, 1e-6f);
  EXPECT_NEAR(static_cast<const SphereShape&>(*r.scene->shapes[1]).radius(), std::cbrt(2.f), 1e-5f);
}

TEST(SceneBuilder, InstancesComposeTransforms) {
  std::string body = std::string(kCamera) + R"(
<shape type="shapegroup" id="g">
  <shape type="sphere"><float name="radius" value="0.25"/></shape>
  <shape type="rectangle"><transform name="to_world"><translate z="1"/></transform></shape>
</shape>
<shape type="instance"><ref id="g"/><transform name="to_world"><translate x="10"/></transform></shape>
<shape type="instance"><ref id="g"/><transform name="to_world"><scale value="2"/><translate x="-10"/></transform></shape>)";
  LoadResult r = load(body);
  // The group's members are built once, in the group's space; each instance places them.
  ASSERT_EQ(r.scene->shapes.size(), 2u);
  for (const auto& s : r.scene->shapes) EXPECT_EQ(s->group, 0u);
  const auto& sphere = static_cast<const SphereShape&>(*r.scene->shapes[0]);
  EXPECT_EQ(sphere.center(), Vec3(0.f));
  for (Vec3 p : mesh_shape(*r.scene, 1).mesh().positions) EXPECT_FLOAT_EQ(p.z, 1.f);
  ASSERT_EQ(r.scene->instances.size(), 2u);
  EXPECT_EQ(r.scene->instances[1].group, 0u);
  // Translate, then scale 2: the rectangle at z = 2, the sphere of radius 0.5 at x = -10.
  const Transform xf = r.scene->instances[1].world_from_object.at(0.f);
  EXPECT_NEAR(xf.apply_point(Vec3(0.f, 0.f, 1.f)).z, 2.f, 1e-6f);
  EXPECT_NEAR(xf.apply_point(Vec3(0.f)).x, -10.f, 1e-6f);
  Ray ray;
  ray.o = Vec3(-10.f, 0.f, -5.f);
  ray.d = Vec3(0.f, 0.f, 1.f);
  SurfaceInteraction si;
  ASSERT_TRUE(r.scene->intersect(ray, si));
  EXPECT_NEAR(si.t, 4.5f, 1e-5f);
  EXPECT_EQ(si.shape, r.scene->shapes[0].get());
  EXPECT_NEAR(si.ng.z, -1.f, 1e-5f);
  ray.o = Vec3(10.2f, 0.3f, -5.f);
  ASSERT_TRUE(r.scene->intersect(ray, si));
  EXPECT_NEAR(si.t, 6.f, 1e-5f);  // the rectangle at z = 1, past the sphere of radius 0.25
  EXPECT_NEAR(si.p.x, 10.2f, 1e-5f);
  EXPECT_EQ(r.scene->num_instanced_triangles(), 4u);
  EXPECT_TRUE(r.unsupported.empty());
}

TEST(SceneBuilder, ShapegroupsDoNotNestAndTheirMembersDoNotMove) {
  const std::string nested = std::string(kCamera) + R"(
<shape type="shapegroup" id="inner"><shape type="sphere"/></shape>
<shape type="shapegroup" id="outer"><shape type="instance"><ref id="inner"/></shape></shape>
<shape type="instance"><ref id="outer"/></shape>)";
  EXPECT_NE(scene_error_of([&] { load(nested); }).find("shapegroups cannot contain instances"), std::string::npos);
  // A member is shared by every instance, so it cannot move on its own: placed at shutter open.
  const std::string moving = R"(<sensor type="perspective"><float name="shutterOpen" value="0"/>
  <float name="shutterClose" value="1"/><film type="hdrfilm"><integer name="width" value="8"/>
  <integer name="height" value="8"/></film></sensor>
<shapegroup id="g"><shape type="sphere"><animation name="toWorld">
  <transform time="0"><translate x="0"/></transform><transform time="1"><translate x="2"/></transform>
</animation></shape></shapegroup>
<shape type="instance"><ref id="g"/></shape>)";
  std::string report;
  try {
    load(moving, {}, "0.6.0");
  } catch (const UnsupportedError& e) {
    report = e.what();
  }
  EXPECT_NE(report.find("a moving shape 'sphere' inside a shapegroup"), std::string::npos) << report;
  LoadOptions allow;
  allow.allow_unsupported = true;
  LoadResult r = load(moving, allow, "0.6.0");
  ASSERT_EQ(r.scene->shapes.size(), 1u);
  EXPECT_EQ(r.scene->shapes[0]->motion, nullptr);
  EXPECT_EQ(static_cast<const SphereShape&>(*r.scene->shapes[0]).center(), Vec3(0.f));
}

TEST(SceneBuilder, MeshFileIsReadOnceForSeveralShapes) {
  TempDir dir;
  dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::string xml = std::string("<scene version=\"3.0.0\">") + kCamera + R"(
<shape type="obj"><string name="filename" value="tri.obj"/></shape>
<shape type="obj"><string name="filename" value="tri.obj"/><transform name="to_world"><translate x="5"/></transform></shape>
</scene>)";
  SceneDesc d = parse_scene_string(xml, (dir.path / "scene.xml").string());
  LoadResult r = load_scene(d, {});
  ASSERT_EQ(r.scene->shapes.size(), 2u);
  EXPECT_FLOAT_EQ(mesh_shape(*r.scene, 1).mesh().positions[0].x - mesh_shape(*r.scene, 0).mesh().positions[0].x, 5.f);
  // The identity-transformed shape shares the cached object-space mesh.
  Scene scene;
  LoadContext ctx(d, {}, scene);
  int loads = 0;
  auto loader = [&] {
    ++loads;
    return MeshData{};
  };
  auto m1 = ctx.cached_mesh("k", loader);
  auto m2 = ctx.cached_mesh("k", loader);
  auto m3 = ctx.cached_mesh("other", loader);
  EXPECT_EQ(loads, 2);
  EXPECT_EQ(m1.get(), m2.get());
  EXPECT_NE(m1.get(), m3.get());
}

TEST(SceneBuilder, MeshErrorsNameTheMeshFileAndTheSceneElement) {
  TempDir dir;
  dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n");
  std::string xml = std::string("<scene version=\"3.0.0\">") + kCamera + R"(
<shape type="obj"><string name="filename" value="bad.obj"/></shape>
</scene>)";
  SceneDesc d = parse_scene_string(xml, (dir.path / "scene.xml").string());
  std::string msg = scene_error_of([&] { (void)load_scene(d, {}); });
  EXPECT_NE(msg.find("bad.obj:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("scene.xml:5"), std::string::npos) << msg;
}

TEST(SceneBuilder, ResolvePathNamesTheLocation) {
  TempDir dir;
  dir.write("a.txt", "x");
  SceneDesc d = desc_of("", "3.0.0", (dir.path / "scene.xml").string());
  Scene scene;
  LoadContext ctx(d, {}, scene);
  EXPECT_EQ(ctx.resolve_path("a.txt", {"s.xml", 3}), (dir.path / "a.txt").string());
  std::string msg = scene_error_of([&] { ctx.resolve_path("missing.obj", {"s.xml", 7}); });
  EXPECT_NE(msg.find("s.xml:7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("missing.obj"), std::string::npos) << msg;
}

TEST(SceneBuilder, EmittersAtTopLevelAndOnShapes) {
  LoadResult r = load(std::string(kCamera) + R"(
<emitter type="point"><point name="position" x="0" y="1" z="0"/><rgb name="intensity" value="2"/></emitter>
<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>)");
  EXPECT_EQ(r.scene->lights.size(), 2u);
  EXPECT_NE(r.scene->shapes[0]->light, nullptr);
  EXPECT_NE(scene_error_of([] { load("<emitter type=\"area\"/>"); }).find("mem/scene.xml:2"), std::string::npos);
}

const char* kUnsupportedScene = R"(<bsdf type="made_up_bsdf" id="mystery">
  <float name="alpha" value="0.1"/>
</bsdf>
<bsdf type="diffuse" id="d">
  <float name="alpha" value="0.3"/>
  <texture type="made_up_texture" name="reflectance"/>
</bsdf>
<bsdf type="made_up_bsdf" id="never_used"/>
<shape type="sphere"><ref id="mystery"/></shape>
<shape type="sphere"><ref id="d"/>
  <medium type="made_up_medium" name="interior"/>
</shape>
<shape type="made_up_shape"/>
<emitter type="made_up_emitter"/>
<sensor type="perspective"><float name="fov" value="30"/><float name="focus_distance" value="3"/>
  <string name="bogus" value="x"/>
  <film type="hdrfilm"><string name="file_format" value="openexr"/><integer name="width" value="8"/>
    <integer name="height" value="8"/></film>
</sensor>)";

TEST(SceneBuilder, UnsupportedItemsAreReportedAllAtOnce) {
  std::vector<UnsupportedItem> items;
  try {
    load(kUnsupportedScene);
    FAIL() << "no UnsupportedError";
  } catch (const UnsupportedError& e) {
    items = e.items();
    std::string msg = e.what();
    EXPECT_NE(msg.find("mem/scene.xml:2: bsdf 'made_up_bsdf' (id 'mystery') (fallback: diffuse"), std::string::npos)
        << msg;
  }
  auto has = [&](int line, const std::string& what) {
    for (const auto& it : items)
      if (it.loc.line == line && it.what.find(what) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(has(2, "bsdf 'made_up_bsdf' (id 'mystery')"));
  EXPECT_TRUE(has(6, "parameter 'alpha' of bsdf 'diffuse'"));
  EXPECT_TRUE(has(7, "texture 'made_up_texture'"));
  EXPECT_TRUE(has(12, "medium 'made_up_medium'"));
  EXPECT_TRUE(has(14, "shape 'made_up_shape'"));
  EXPECT_TRUE(has(15, "emitter 'made_up_emitter'"));
  EXPECT_TRUE(has(17, "parameter 'bogus' of sensor 'perspective'"));
  // Not reported: the unread parameter of the unsupported BSDF (the BSDF is), the unreferenced
  // definition, and the image-neutral focus_distance / file_format.
  EXPECT_EQ(items.size(), 7u);
  for (const auto& it : items) {
    EXPECT_EQ(it.loc.file, "mem/scene.xml");
    EXPECT_FALSE(it.fallback.empty());
  }
}

TEST(SceneBuilder, AllowUnsupportedSubstitutesFallbacks) {
  LoadOptions opt;
  opt.allow_unsupported = true;
  LoadResult r = load(kUnsupportedScene, opt);
  EXPECT_EQ(r.unsupported.size(), 7u);
  size_t warnings = 0, notes = 0;
  for (const auto& m : r.messages) (m.level == LoadMessage::Level::Warning ? warnings : notes) += 1;
  EXPECT_EQ(warnings, 7u);
  EXPECT_EQ(notes, 2u);  // focus_distance, file_format
  ASSERT_EQ(r.scene->shapes.size(), 2u);  // the made-up shape is skipped
  EXPECT_NE(r.scene->shapes[0]->bsdf, nullptr);
  EXPECT_EQ(r.scene->shapes[0]->bsdf, r.scene->shapes[0]->bsdf);
  EXPECT_TRUE(r.scene->lights.empty());  // the made-up emitter is dropped
}

TEST(SceneBuilder, UnsupportedSensorFilterIntegratorAndInstancedEmitter) {
  const std::string body = R"(<integrator type="made_up_integrator"><integer name="max_depth" value="4"/></integrator>
<sensor type="spherical"><float name="fov" value="30"/><float name="aperture_radius" value="0.1"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
    <rfilter type="mitchell"/></film>
  <sampler type="made_up_sampler"><integer name="sample_count" value="9"/></sampler>
</sensor>
<shape type="shapegroup" id="g">
  <shape type="sphere"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</shape>
<shape type="instance"><ref id="g"/></shape>
<shape type="instance"><ref id="g"/></shape>)";
  std::vector<UnsupportedItem> items;
  try {
    load(body);
  } catch (const UnsupportedError& e) {
    items = e.items();
  }
  std::vector<std::pair<int, std::string>> expected = {{2, "integrator 'made_up_integrator'"},
                                                       {3, "sensor 'spherical'"},
                                                       {5, "rfilter 'mitchell'"},
                                                       {6, "sampler 'made_up_sampler'"},
                                                       {9, "area emitter inside a shapegroup"}};
  ASSERT_EQ(items.size(), expected.size());
  for (const auto& [line, what] : expected) {
    bool found = false;
    for (const auto& it : items) found |= it.loc.line == line && it.what.find(what) != std::string::npos;
    EXPECT_TRUE(found) << line << " " << what;
  }
  LoadOptions opt;
  opt.allow_unsupported = true;
  LoadResult r = load(body, opt);
  EXPECT_EQ(r.scene->integrator.type, IntegratorType::Path);
  EXPECT_EQ(r.scene->film.filter->name(), "gaussian");
  EXPECT_EQ(r.scene->sampler.type, SamplerType::Independent);
  EXPECT_EQ(r.scene->sampler.sample_count, 9);
  EXPECT_EQ(r.scene->shapes.size(), 1u);  // the group's sphere, once
  EXPECT_EQ(r.scene->instances.size(), 2u);
  EXPECT_TRUE(r.scene->lights.empty());
  EXPECT_NE(r.scene->camera, nullptr);
}

TEST(SceneBuilder, UnreferencedDefinitionsAreNotReported) {
  // As in the bathroom scene: a top-level bumpmap nobody uses, whose inner BSDF has the id.
  LoadResult r = load(std::string(kCamera) + R"(
<bsdf type="made_up_bumpmap">
  <texture type="made_up_texture" name="map"/>
  <bsdf type="twosided" id="Floor"><bsdf type="diffuse"/></bsdf>
</bsdf>
<shape type="sphere"><ref id="Floor"/></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
}

TEST(SceneBuilder, BuilderErrorsNameFileAndLine) {
  std::string msg = scene_error_of([] {
    load("<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/>\n"
         "<film type=\"hdrfilm\">\n<integer name=\"width\" value=\"0\"/></film></sensor>");
  });
  EXPECT_NE(msg.find("mem/scene.xml:4"), std::string::npos) << msg;
  msg = scene_error_of([] { load("<shape type=\"sphere\">\n<float name=\"radius\" value=\"-1\"/></shape>"); });
  EXPECT_NE(msg.find("mem/scene.xml:3"), std::string::npos) << msg;
  msg = scene_error_of([] { load("<shape type=\"obj\">\n<string name=\"filename\" value=\"nothere.obj\"/></shape>"); });
  EXPECT_NE(msg.find("mem/scene.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nothere.obj"), std::string::npos) << msg;
  msg = scene_error_of([] { load("<shape type=\"sphere\"><bsdf type=\"diffuse\"/>\n<bsdf type=\"diffuse\"/></shape>"); });
  EXPECT_NE(msg.find("mem/scene.xml:3"), std::string::npos) << msg;
}

TEST(SceneBuilder, NoSensorGivesAFittedDefaultCamera) {
  LoadResult r = load("<shape type=\"sphere\"><float name=\"radius\" value=\"2\"/></shape>");
  ASSERT_NE(r.scene->camera, nullptr);
  Ray ray = r.scene->camera->generate_ray(Vec2(384.f, 288.f), Vec2(0.5f, 0.5f));
  EXPECT_NEAR(ray.d.z, 1.f, 1e-4f);  // looks along +z at the scene
  EXPECT_LT(ray.o.z, -2.f);
}

class SharedSceneLoads : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedSceneLoads, WithAllowUnsupported) {
  std::string path = test::shared_path(std::string("scenes/") + GetParam() + "/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  LoadOptions opt;
  opt.allow_unsupported = true;
  LoadResult r = load_scene(parse_scene_file(path), opt);
  EXPECT_FALSE(r.scene->shapes.empty());
  EXPECT_NE(r.scene->camera, nullptr);
  for (const auto& it : r.unsupported) {
    EXPECT_EQ(it.loc.file, path);
    EXPECT_GT(it.loc.line, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Small, SharedSceneLoads, ::testing::Values("cornell-box", "veach-mis", "veach-bidir"));

}  // namespace
}  // namespace tessera
