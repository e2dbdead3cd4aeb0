// Media in scene files: interior/exterior media on shapes (nested and referenced), the camera's
// medium, the null BSDF of bare medium boundaries, Mitsuba 0.6 and 3 parameters, errors with file
// and line, and what each integrator does with media (volpath tracks them, path warns, others are
// substituted with a note).
#include "tessera/medium/material_presets.h"
#include "tessera/scene/load_context.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using test::scene_error_of;

LoadResult load(const std::string& body, const std::string& version = "0.6.0", LoadOptions opt = {}) {
  return load_scene(parse_scene_string("<scene version=\"" + version + "\">\n" + body + "\n</scene>\n", "mem/scene.xml"), opt);
}

size_t count_messages(const LoadResult& r, LoadMessage::Level level, const std::string& text) {
  size_t n = 0;
  for (const auto& m : r.messages) n += m.level == level && m.text.find(text) != std::string::npos;
  return n;
}

// staircase2's glass: a dielectric shape with a nested absorbing medium.
const char* kGlassWithMedium = R"(<shape type="sphere">
  <bsdf type="dielectric"/>
  <medium type="homogeneous" name="interior">
    <rgb name="sigmaS" value="0, 0, 0"/>
    <rgb name="sigmaA" value="0.5, 0.2, 0.4"/>
  </medium>
</shape>)";

TEST(MediumLoader, VolpathTracksANestedInteriorMedium) {
  LoadResult r = load(std::string("<integrator type=\"volpath\"/>\n") + kGlassWithMedium);
  const Scene& s = *r.scene;
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_TRUE(s.shapes[0]->medium_interface);
  ASSERT_NE(s.shapes[0]->interior, nullptr);
  EXPECT_EQ(s.shapes[0]->exterior, nullptr);
  EXPECT_TRUE(s.has_media());
  EXPECT_EQ(s.integrator.type, IntegratorType::VolPath);
  EXPECT_FALSE(s.shapes[0]->bsdf->is_null());
  // Beer-Lambert with the declared sigma_a: 0.5, 0.2, 0.4 per unit.
  Rgb tr = s.shapes[0]->interior->transmittance(Ray{Vec3(0.f), Vec3(1.f, 0.f, 0.f)}, 2.f);
  EXPECT_NEAR(tr.r, std::exp(-1.f), 1e-6f);
  EXPECT_NEAR(tr.g, std::exp(-0.4f), 1e-6f);
  EXPECT_NEAR(tr.b, std::exp(-0.8f), 1e-6f);
  EXPECT_TRUE(s.shapes[0]->interior->absorbing_only());
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Warning, "media"), 0u);
}

TEST(MediumLoader, PathWarnsOnceThatItIgnoresMedia) {
  LoadResult r = load(std::string("<integrator type=\"path\"/>\n") + kGlassWithMedium + kGlassWithMedium);
  EXPECT_EQ(r.scene->integrator.type, IntegratorType::Path);
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Warning, "ignores the participating media"), 1u);
  LoadOptions opt;
  opt.integrator = "volpath";
  EXPECT_EQ(load(std::string("<integrator type=\"path\"/>\n") + kGlassWithMedium, "0.6.0", opt).scene->integrator.type,
            IntegratorType::VolPath);
}

TEST(MediumLoader, VolpathWithoutMediaIsThePathTracer) {
  LoadResult r = load("<integrator type=\"volpath\"><integer name=\"maxDepth\" value=\"7\"/></integrator>\n<shape type=\"sphere\"/>");
  EXPECT_EQ(r.scene->integrator.type, IntegratorType::Path);
  EXPECT_EQ(r.scene->integrator.max_depth, 7);
  for (const auto& m : r.messages) EXPECT_EQ(m.text.find("volpath"), std::string::npos) << m.text;
}

TEST(MediumLoader, UnimplementedIntegratorsAreSubstitutedWithANote) {
  for (const char* type : {"ppm", "pssmlt", "photonmapper", "vpl"}) {
    LoadResult r = load(std::string("<integrator type=\"") + type +
                        "\"><integer name=\"maxDepth\" value=\"9\"/><boolean name=\"lightImage\" value=\"true\"/>"
                        "<integer name=\"photonCount\" value=\"1000\"/></integrator>\n" + kGlassWithMedium);
    EXPECT_EQ(r.scene->integrator.type, IntegratorType::VolPath) << type;  // the scene has a medium
    EXPECT_EQ(r.scene->integrator.max_depth, 9) << type;
    EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "rendered by Tessera's path tracer"), 1u) << type;
    EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "caustics of point lights"), 1u) << type;
  }
  // Without media the substitute is the plain path tracer.
  EXPECT_EQ(load("<integrator type=\"ppm\"/>\n<shape type=\"sphere\"/>").scene->integrator.type, IntegratorType::Path);
}

TEST(MediumLoader, ReferencedMediaBareBoundariesAndTheCameraMedium) {
  LoadResult r = load(R"(<integrator type="volpath"/>
<medium type="homogeneous" id="fog">
  <rgb name="sigmaT" value="0.1"/><rgb name="albedo" value="0.9"/>
  <phase type="hg"><float name="g" value="0.6"/></phase>
</medium>
<shape type="sphere"><ref name="exterior" id="fog"/><ref name="interior" id="fog"/></shape>
<sensor type="perspective"><ref id="fog"/>
  <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film>
</sensor>)");
  const Scene& s = *r.scene;
  ASSERT_EQ(s.media.size(), 1u);  // built once, shared
  EXPECT_EQ(s.shapes[0]->interior, s.media[0].get());
  EXPECT_EQ(s.shapes[0]->exterior, s.media[0].get());
  EXPECT_EQ(s.camera_medium, s.media[0].get());
  EXPECT_TRUE(s.shapes[0]->bsdf->is_null());  // a boundary without a BSDF of its own
  // HG g = 0.6 scatters forward.
  const PhaseFunction& phase = s.media[0]->phase();
  EXPECT_GT(phase.eval(Vec3(0.f, 0.f, -1.f), Vec3(0.f, 0.f, 1.f)), 5.f * phase.eval(Vec3(0.f, 0.f, -1.f), Vec3(0.f, 0.f, -1.f)));
}

TEST(MediumLoader, Mitsuba3ParametersAndScale) {
  LoadResult r = load(R"(<integrator type="volpath"/>
<shape type="sphere"><medium type="homogeneous" name="interior">
  <rgb name="sigma_t" value="2"/><float name="scale" value="0.5"/></medium></shape>)", "3.0.0");
  const Medium& m = *r.scene->shapes[0]->interior;
  EXPECT_NEAR(m.transmittance(Ray{Vec3(0.f), Vec3(0.f, 1.f, 0.f)}, 1.f).g, std::exp(-1.f), 1e-6f);
  EXPECT_FALSE(m.absorbing_only());  // Mitsuba 3's default albedo is 0.75
}

TEST(MediumLoader, MeasuredMaterialPreset) {
  // Mitsuba 0.6 scales the presets (per mm) by 100 and then by `scale`.
  LoadResult r = load(R"(<shape type="sphere"><medium type="homogeneous" name="interior">
  <string name="material" value="Ketchup"/><float name="scale" value="0.01"/></medium></shape>)");
  MeasuredMedium ketchup;
  ASSERT_TRUE(lookup_measured_medium("ketchup", ketchup));
  const Rgb sigma_t = ketchup.sigma_s + ketchup.sigma_a;
  Rgb tr = r.scene->shapes[0]->interior->transmittance(Ray{Vec3(0.f), Vec3(1.f, 0.f, 0.f)}, 1.f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(tr[c], std::exp(-sigma_t[c]), 1e-5f) << c;
}

TEST(MediumLoader, ErrorsNameFileLineAndField) {
  std::string e = scene_error_of([] {
    load("<shape type=\"sphere\">\n<medium type=\"homogeneous\"/>\n</shape>");
  });
  EXPECT_NE(e.find("mem/scene.xml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("interior"), std::string::npos) << e;
  e = scene_error_of([] {
    load("<shape type=\"sphere\"><medium type=\"homogeneous\" name=\"interior\">\n"
         "<string name=\"material\" value=\"Marmalade\"/></medium></shape>");
  });
  EXPECT_NE(e.find("mem/scene.xml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("Marmalade"), std::string::npos) << e;
  EXPECT_NE(e.find("Ketchup"), std::string::npos) << e;  // the known names are listed
  e = scene_error_of([] {
    load("<shape type=\"sphere\"><medium type=\"homogeneous\" name=\"interior\">\n"
         "<rgb name=\"sigmaA\" value=\"1\"/><rgb name=\"albedo\" value=\"0.5\"/></medium></shape>");
  });
  EXPECT_NE(e.find("not both"), std::string::npos) << e;
  e = scene_error_of([] {
    load("<shape type=\"sphere\"><medium type=\"homogeneous\" name=\"interior\">\n"
         "<phase type=\"hg\">\n<float name=\"g\" value=\"1.5\"/></phase></medium></shape>");
  });
  EXPECT_NE(e.find("mem/scene.xml:4"), std::string::npos) << e;
  e = scene_error_of([] {
    load("<shape type=\"sphere\"><medium type=\"homogeneous\" name=\"interior\">\n"
         "<rgb name=\"albedo\" value=\"1.2\"/></medium></shape>");
  });
  EXPECT_NE(e.find("albedo"), std::string::npos) << e;
}

}  // namespace
}  // namespace tessera
