// Mitsuba XML parser: every element, both syntaxes, substitution, refs, includes, and errors that
// name file and line.
#include "tessera/scene/scene_desc.h"

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

SceneDesc parse(const std::string& body, const std::string& version = "3.0.0", const ParseOptions& opt = {}) {
  return parse_scene_string("<scene version=\"" + version + "\">\n" + body + "\n</scene>\n", "test.xml", opt);
}

const Property& prop(const SceneNode& n, const std::string& name) {
  const Property* p = n.find(name);
  EXPECT_NE(p, nullptr) << name;
  static Property none;
  return p ? *p : none;
}

void expect_matrix_near(const Matrix4& a, const Matrix4& b, double tol = 1e-6) {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(a.m[i][j], b.m[i][j], tol) << "entry " << i << "," << j;
}

TEST(XmlParser, ScalarProperties) {
  auto d = parse(R"(<integrator type="path">
  <integer name="max_depth" value="8"/>
  <float name="f" value="-1.5e-3"/>
  <boolean name="b" value="true"/>
  <string name="s" value="hello world"/>
</integrator>)");
  ASSERT_EQ(d.root->children.size(), 1u);
  const SceneNode& n = *d.root->children[0];
  EXPECT_EQ(n.tag, "integrator");
  EXPECT_EQ(n.type, "path");
  EXPECT_EQ(n.loc.file, "test.xml");
  EXPECT_EQ(n.loc.line, 2);
  EXPECT_EQ(prop(n, "max_depth").type, PropType::Integer);
  EXPECT_EQ(n.get_int("max_depth", 0), 8);
  EXPECT_FLOAT_EQ(n.get_float("f", 0), -1.5e-3f);
  EXPECT_TRUE(n.get_bool("b", false));
  EXPECT_EQ(n.get_string("s", ""), "hello world");
  EXPECT_EQ(prop(n, "s").loc.line, 6);
  EXPECT_EQ(d.version_major, 3);
  EXPECT_EQ(d.version, "3.0.0");
}

TEST(XmlParser, GettersMarkUsedAndAcceptCompatibleTypes) {
  auto d = parse(R"(<bsdf type="diffuse" id="d">
  <integer name="n" value="3"/>
  <float name="grey" value="0.25"/>
  <string name="unused" value="x"/>
</bsdf>)");
  const SceneNode& n = *d.root->children[0];
  EXPECT_FALSE(prop(n, "n").used);
  EXPECT_FLOAT_EQ(n.get_float("n", 0.f), 3.f);  // an integer where a float is expected is fine
  EXPECT_TRUE(prop(n, "n").used);
  EXPECT_EQ(n.get_color("grey", Rgb()), Rgb(0.25f));  // a float where a colour is expected is grey
  EXPECT_TRUE(prop(n, "grey").used);
  EXPECT_FALSE(prop(n, "unused").used);
  EXPECT_TRUE(n.has("unused"));
  EXPECT_FALSE(prop(n, "unused").used);  // has() is not a read
  EXPECT_FLOAT_EQ(n.get_float("missing", 7.f), 7.f);
  EXPECT_EQ(n.describe(), "bsdf 'diffuse' (id 'd')");
}

TEST(XmlParser, WrongTypeNamesPropertyNodeFileAndLine) {
  auto d = parse(R"(<bsdf type="diffuse">

  <string name="alpha" value="rough"/>
</bsdf>)");
  const SceneNode& n = *d.root->children[0];
  std::string msg = scene_error_of([&] { n.get_float("alpha", 0.f); });
  EXPECT_NE(msg.find("test.xml:4"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'alpha'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("bsdf 'diffuse'"), std::string::npos) << msg;
  EXPECT_NE(scene_error_of([&] { n.get_color("alpha", Rgb()); }).find("test.xml:4"), std::string::npos);
  EXPECT_NE(scene_error_of([&] { n.get_bool("alpha", false); }).find("must be a boolean"), std::string::npos);
}

TEST(XmlParser, RgbForms) {
  auto d = parse(R"(<bsdf type="diffuse">
  <rgb name="a" value="0.1, 0.2, 0.3"/>
  <rgb name="b" value="0.1 0.2 0.3"/>
  <rgb name="c" value="  0.5 "/>
  <srgb name="d" value="#ff8000"/>
  <srgb name="e" value="0.5, 0.5, 0.5"/>
</bsdf>)");
  const SceneNode& n = *d.root->children[0];
  EXPECT_EQ(n.get_color("a", Rgb()), Rgb(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(n.get_color("b", Rgb()), Rgb(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(n.get_color("c", Rgb()), Rgb(0.5f));
  Rgb dcol = n.get_color("d", Rgb());
  EXPECT_FLOAT_EQ(dcol.r, 1.f);
  EXPECT_NEAR(dcol.g, srgb_to_linear(128.f / 255.f), 1e-6f);
  EXPECT_FLOAT_EQ(dcol.b, 0.f);
  EXPECT_NEAR(n.get_color("e", Rgb()).g, 0.214041f, 1e-5f);  // sRGB 0.5 linearised
}

TEST(XmlParser, SpectrumForms) {
  auto d = parse(R"(<emitter type="point">
  <spectrum name="grey" value="0.7"/>
  <spectrum name="three" value="0.1, 0.2, 0.3"/>
  <spectrum name="flat" value="360:2, 830:2"/>
  <spectrum name="red" value="590:0, 600:1, 610:0"/>
  <blackbody name="warm" temperature="3000K"/>
  <blackbody name="warm2" temperature="3000" scale="2"/>
</emitter>)");
  const SceneNode& n = *d.root->children[0];
  EXPECT_EQ(n.get_color("grey", Rgb()), Rgb(0.7f));
  EXPECT_EQ(n.get_color("three", Rgb()), Rgb(0.1f, 0.2f, 0.3f));
  // A flat spectrum keeps its luminance: Y = sum(ybar * v) / sum(ybar) = v.
  Rgb flat = n.get_color("flat", Rgb());
  EXPECT_NEAR(flat.luminance(), 2.f, 2e-3f);
  EXPECT_GT(flat.r, flat.b);  // equal-energy white is pinkish in Rec. 709
  Rgb red = n.get_color("red", Rgb());
  EXPECT_GT(red.r, 0.f);
  EXPECT_GT(red.r, 10.f * red.b);
  Rgb warm = n.get_color("warm", Rgb()), warm2 = n.get_color("warm2", Rgb());
  EXPECT_TRUE(warm.is_finite());
  EXPECT_GT(warm.r, warm.b);
  EXPECT_NEAR(warm2.r, 2.f * warm.r, 1e-4f * warm2.r);
  EXPECT_NEAR(warm2.b, 2.f * warm.b, 1e-4f * warm2.r);
}

TEST(XmlParser, PointsAndVectors) {
  auto d = parse(R"(<shape type="sphere">
  <point name="center" x="1" y="2" z="3"/>
  <point name="p2" x="1"/>
  <vector name="v" value="4, 5, 6"/>
</shape>)");
  const SceneNode& n = *d.root->children[0];
  EXPECT_EQ(n.get_vector("center", Vec3()), Vec3(1, 2, 3));
  EXPECT_EQ(n.get_vector("p2", Vec3(9.f)), Vec3(1, 0, 0));
  EXPECT_EQ(n.get_vector("v", Vec3()), Vec3(4, 5, 6));
}

TEST(XmlParser, TransformElements) {
  auto d = parse(R"(<shape type="obj">
  <transform name="m"><matrix value="1 2 3 4  0 1 0 5  0 0 1 6  0 0 0 1"/></transform>
  <transform name="t"><translate x="1" y="2" z="3"/></transform>
  <transform name="t3"><translate value="1, 2, 3"/></transform>
  <transform name="r"><rotate y="1" angle="90"/></transform>
  <transform name="r3"><rotate value="0, 1, 0" angle="90"/></transform>
  <transform name="su"><scale value="2"/></transform>
  <transform name="sx"><scale x="2" z="4"/></transform>
  <transform name="s3"><scale value="2, 3, 4"/></transform>
  <transform name="empty"/>
</shape>)");
  const SceneNode& n = *d.root->children[0];
  Matrix4 m = Matrix4::from_row_major({1, 2, 3, 4, 0, 1, 0, 5, 0, 0, 1, 6, 0, 0, 0, 1});
  expect_matrix_near(n.get_transform("m", {}).matrix(), m);
  expect_matrix_near(n.get_transform("t", {}).matrix(), Transform::translate(Vec3(1, 2, 3)).matrix());
  expect_matrix_near(n.get_transform("t3", {}).matrix(), Transform::translate(Vec3(1, 2, 3)).matrix());
  expect_matrix_near(n.get_transform("r", {}).matrix(), Transform::rotate(Vec3(0, 1, 0), 90.f).matrix());
  expect_matrix_near(n.get_transform("r3", {}).matrix(), Transform::rotate(Vec3(0, 1, 0), 90.f).matrix());
  // Right-handed rotation about +y by 90 degrees takes +x to -z.
  Vec3 x = n.get_transform("r", {}).apply_vector(Vec3(1, 0, 0));
  EXPECT_NEAR(x.z, -1.f, 1e-6f);
  expect_matrix_near(n.get_transform("su", {}).matrix(), Transform::scale(Vec3(2.f)).matrix());
  expect_matrix_near(n.get_transform("sx", {}).matrix(), Transform::scale(Vec3(2, 1, 4)).matrix());
  expect_matrix_near(n.get_transform("s3", {}).matrix(), Transform::scale(Vec3(2, 3, 4)).matrix());
  EXPECT_TRUE(n.get_transform("empty", Transform::scale(Vec3(3.f))).is_identity());
  // The inverse is kept consistent.
  expect_matrix_near(n.get_transform("m", {}).inverse_matrix(), *m.inverse());
}

TEST(XmlParser, TransformCompositionIsDocumentOrderLeftMultiplied) {
  auto d = parse(R"(<shape type="obj">
  <transform name="to_world">
    <translate x="1"/>
    <rotate z="1" angle="90"/>
    <scale value="2"/>
    <matrix value="1 0 0 0  0 1 0 0  0 0 1 7  0 0 0 1"/>
  </transform>
</shape>)");
  Transform expected = Transform::translate(Vec3(0, 0, 7)) * Transform::scale(Vec3(2.f)) *
                       Transform::rotate(Vec3(0, 0, 1), 90.f) * Transform::translate(Vec3(1, 0, 0));
  Transform t = d.root->children[0]->get_transform("to_world", {});
  expect_matrix_near(t.matrix(), expected.matrix());
  // The origin is translated to (1,0,0), rotated to (0,1,0), scaled to (0,2,0), moved to (0,2,7).
  Vec3 p = t.apply_point(Vec3(0.f));
  EXPECT_NEAR(p.x, 0.f, 1e-6f);
  EXPECT_NEAR(p.y, 2.f, 1e-6f);
  EXPECT_NEAR(p.z, 7.f, 1e-6f);
}

TEST(XmlParser, LookAt) {
  auto d = parse(R"(<sensor type="perspective">
  <transform name="to_world">
    <lookat origin="1, 2, 3" target="1, 2, 4" up="0, 1, 0"/>
  </transform>
</sensor>)");
  Transform t = d.root->children[0]->get_transform("to_world", {});
  auto expected = Transform::look_at(Vec3(1, 2, 3), Vec3(1, 2, 4), Vec3(0, 1, 0));
  ASSERT_TRUE(expected);
  expect_matrix_near(t.matrix(), expected->matrix());
  Vec3 fwd = t.apply_vector(Vec3(0, 0, 1));
  EXPECT_NEAR(fwd.z, 1.f, 1e-6f);
  Vec3 o = t.apply_point(Vec3(0.f));
  EXPECT_EQ(o, Vec3(1, 2, 3));
}

TEST(XmlParser, OldVersionNamesAreSnakeCased) {
  auto d = parse(R"(<integrator type="path"><integer name="maxDepth" value="5"/></integrator>
<sensor type="perspective">
  <string name="fovAxis" value="y"/>
  <transform name="toWorld"><translate x="1"/></transform>
  <sampler type="sobol"><integer name="sampleCount" value="4"/></sampler>
  <film type="hdrfilm"><integer name="cropOffsetX" value="4"/></film>
</sensor>
<bsdf type="dielectric"><float name="intIOR" value="1.5"/><float name="extIOR" value="1"/>
  <rgb name="specularReflectance" value="1"/></bsdf>
<bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.5"/></bsdf>
<bsdf type="roughplastic"><texture type="bitmap" name="diffuseReflectance">
  <string name="filterType" value="ewa"/></texture></bsdf>
<default name="myParam" value="1"/>)",
                 "0.5.0");
  EXPECT_EQ(d.version_major, 0);
  const auto& c = d.root->children;
  EXPECT_TRUE(c[0]->has("max_depth"));
  EXPECT_EQ(prop(*c[0], "max_depth").written_name, "maxDepth");
  EXPECT_TRUE(c[1]->has("fov_axis"));
  EXPECT_TRUE(c[1]->has("to_world"));
  EXPECT_TRUE(c[1]->children[0]->has("sample_count"));
  EXPECT_TRUE(c[1]->children[1]->has("crop_offset_x"));
  EXPECT_TRUE(c[2]->has("int_ior"));
  EXPECT_TRUE(c[2]->has("ext_ior"));
  EXPECT_TRUE(c[2]->has("specular_reflectance"));
  EXPECT_TRUE(c[3]->has("reflectance"));  // Mitsuba 0.6's diffuse synonym
  EXPECT_EQ(prop(*c[3], "reflectance").written_name, "diffuseReflectance");
  // A nested object's name is normalised too; only the diffuse synonym is renamed.
  ASSERT_NE(c[4]->named_child("diffuse_reflectance"), nullptr);
  EXPECT_TRUE(c[4]->named_child("diffuse_reflectance")->has("filter_type"));
}

TEST(XmlParser, OldUvOffsetAndScaleBecomeToUv) {
  auto d = parse(R"(<texture type="bitmap">
  <float name="uscale" value="2"/><float name="vscale" value="4"/>
  <float name="uoffset" value="0.5"/>
</texture>)",
                 "0.6.0");
  const SceneNode& t = *d.root->children[0];
  EXPECT_FALSE(t.has("uscale"));
  ASSERT_TRUE(t.has("to_uv"));
  // Mitsuba 0.6: uv' = uv * scale + offset.
  Vec3 uv = t.get_transform("to_uv", {}).apply_point(Vec3(1.f, 1.f, 0.f));
  EXPECT_FLOAT_EQ(uv.x, 2.5f);
  EXPECT_FLOAT_EQ(uv.y, 4.f);
  EXPECT_EQ(prop(t, "to_uv").loc.line, 3);
  // Mitsuba 3 scenes keep their parameters as written.
  auto d3 = parse("<texture type=\"bitmap\"><float name=\"uscale\" value=\"2\"/></texture>");
  EXPECT_TRUE(d3.root->children[0]->has("uscale"));
}

TEST(XmlParser, NewVersionNamesAreKept) {
  auto d = parse(R"(<integrator type="path"><integer name="max_depth" value="5"/>
  <integer name="maxDepth" value="6"/></integrator>)",
                 "2.1.0");
  EXPECT_EQ(d.version_major, 2);
  EXPECT_EQ(d.root->children[0]->get_int("max_depth", 0), 5);
  EXPECT_EQ(d.root->children[0]->get_int("maxDepth", 0), 6);  // not Mitsuba 3 syntax: left as is
}

TEST(XmlParser, DefaultsSubstitutionAndDefines) {
  const std::string body = R"(<default name="spp" value="16"/>
<default name="res" value="64"/>
<default name="spp_extra" value="3"/>
<sampler type="$type">
  <integer name="sample_count" value="$spp"/>
  <integer name="other" value="$spp_extra"/>
  <string name="mixed" value="a$res-b"/>
  <string name="dollar" value="cost: $ 5"/>
</sampler>)";
  ParseOptions opt;
  opt.defines["type"] = "independent";
  auto d = parse(body, "3.0.0", opt);
  const SceneNode& s = *d.root->children[0];
  EXPECT_EQ(s.type, "independent");
  EXPECT_EQ(s.get_int("sample_count", 0), 16);
  EXPECT_EQ(s.get_int("other", 0), 3);  // the longest defined name wins
  EXPECT_EQ(s.get_string("mixed", ""), "a64-b");
  EXPECT_EQ(s.get_string("dollar", ""), "cost: $ 5");
  opt.defines["spp"] = "256";  // -D overrides <default>
  EXPECT_EQ(parse(body, "3.0.0", opt).root->children[0]->get_int("sample_count", 0), 256);
}

TEST(XmlParser, UndefinedParameterNamesFileAndLine) {
  std::string msg = scene_error_of([] { parse("<sampler type=\"sobol\">\n<integer name=\"n\" value=\"$nope\"/></sampler>"); });
  EXPECT_NE(msg.find("test.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("$nope"), std::string::npos) << msg;
  // A default declared after its use does not count (Mitsuba reads in order).
  msg = scene_error_of([] { parse("<sampler type=\"$t\"/>\n<default name=\"t\" value=\"sobol\"/>"); });
  EXPECT_NE(msg.find("test.xml:2"), std::string::npos) << msg;
}

TEST(XmlParser, RefsAliasesAndIds) {
  auto d = parse(R"(<texture type="checkerboard" id="tex"/>
<bsdf type="diffuse" id="mat">
  <ref name="reflectance" id="tex"/>
</bsdf>
<alias id="mat" as="mat2"/>
<shape type="sphere"><ref id="mat"/></shape>
<shape type="sphere"><ref id="mat2"/></shape>)");
  const auto& c = d.root->children;
  ASSERT_EQ(c.size(), 4u);
  auto refl = c[1]->named_child("reflectance");
  ASSERT_NE(refl, nullptr);
  EXPECT_EQ(refl.get(), c[0].get());  // shared, not copied
  EXPECT_EQ(c[2]->children[0].get(), c[1].get());
  EXPECT_EQ(c[3]->children[0].get(), c[1].get());
  EXPECT_EQ(c[2]->child_names[0], "");
  EXPECT_EQ(c[2]->children_with_tag("bsdf").size(), 1u);

  std::string msg = scene_error_of([] { parse("<shape type=\"sphere\">\n<ref id=\"later\"/></shape>\n<bsdf type=\"diffuse\" id=\"later\"/>"); });
  EXPECT_NE(msg.find("test.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'later'"), std::string::npos) << msg;
  msg = scene_error_of([] { parse("<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"diffuse\" id=\"a\"/>"); });
  EXPECT_NE(msg.find("test.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("duplicate id 'a'"), std::string::npos) << msg;
  msg = scene_error_of([] { parse("<bsdf type=\"twosided\" id=\"self\"><ref id=\"self\"/></bsdf>"); });
  EXPECT_NE(msg.find("unknown id 'self'"), std::string::npos) << msg;
}

TEST(XmlParser, ShapegroupAndInstanceStayNodes) {
  auto d = parse(R"(<shape type="shapegroup" id="g">
  <shape type="sphere"/>
  <shape type="obj"><string name="filename" value="a.obj"/></shape>
</shape>
<shape type="instance">
  <ref id="g"/>
  <transform name="to_world"><translate x="2"/></transform>
</shape>)");
  const auto& c = d.root->children;
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0]->type, "shapegroup");
  EXPECT_EQ(c[0]->children.size(), 2u);
  EXPECT_EQ(c[1]->type, "instance");
  EXPECT_EQ(c[1]->children[0].get(), c[0].get());
}

TEST(XmlParser, IncludesResolveRelativeToTheIncludingFile) {
  TempDir dir;
  dir.write("parts/materials.xml", R"(<scene version="0.6.0">
  <default name="refl" value="0.25"/>
  <bsdf type="diffuse" id="white">
    <rgb name="diffuseReflectance" value="$refl"/>
  </bsdf>
  <include filename="more.xml"/>
</scene>)");
  dir.write("parts/more.xml", "<scene version=\"3.0.0\">\n\n<bsdf type=\"diffuse\" id=\"other\"/>\n</scene>\n");
  std::string main = dir.write("main.xml", R"(<scene version="0.6.0">
  <include filename="parts/materials.xml"/>
  <shape type="sphere"><ref id="white"/></shape>
</scene>)");
  SceneDesc d = parse_scene_file(main);
  ASSERT_EQ(d.root->children.size(), 3u);
  const SceneNode& white = *d.root->children[0];
  EXPECT_EQ(white.id, "white");
  EXPECT_EQ(white.get_color("reflectance", Rgb()), Rgb(0.25f));
  EXPECT_EQ(white.loc.file, (dir.path / "parts/materials.xml").string());
  EXPECT_EQ(white.loc.line, 3);
  EXPECT_EQ(d.root->children[1]->loc.file, (dir.path / "parts/more.xml").string());
  EXPECT_EQ(d.root->children[1]->loc.line, 3);
  EXPECT_EQ(d.root->children[2]->children[0].get(), &white);
  EXPECT_EQ(d.base_dir, dir.path.string());
  EXPECT_EQ(d.file, main);
}

TEST(XmlParser, IncludeErrors) {
  TempDir dir;
  dir.write("a.xml", "<scene version=\"3.0.0\">\n<include filename=\"b.xml\"/>\n</scene>");
  dir.write("b.xml", "<scene version=\"3.0.0\">\n\n<include filename=\"a.xml\"/>\n</scene>");
  dir.write("bad.xml", "<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\">\n<float name=\"x\" value=\"1.0x\"/>\n</bsdf></scene>");
  std::string msg = scene_error_of([&] { parse_scene_file((dir.path / "a.xml").string()); });
  EXPECT_NE(msg.find("b.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cycle"), std::string::npos) << msg;
  msg = scene_error_of([&] {
    parse_scene_string("<scene version=\"3.0.0\">\n<include filename=\"bad.xml\"/>\n</scene>",
                       (dir.path / "main.xml").string());
  });
  EXPECT_NE(msg.find("bad.xml:3"), std::string::npos) << msg;
  msg = scene_error_of([&] {
    parse_scene_string("<scene version=\"3.0.0\">\n<include filename=\"missing.xml\"/>\n</scene>",
                       (dir.path / "main.xml").string());
  });
  EXPECT_NE(msg.find("main.xml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("missing.xml"), std::string::npos) << msg;
}

struct BadInput {
  const char* body;
  int line;           // expected line in the message
  const char* words;  // expected fragment
};

TEST(XmlParser, ErrorsNameFileAndLine) {
  const BadInput cases[] = {
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"1.0x\"/></bsdf>", 3, "1.0x"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"nan\"/></bsdf>", 3, "nan"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"inf\"/></bsdf>", 3, "inf"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"1e39\"/></bsdf>", 3, "1e39"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"\"/></bsdf>", 3, "invalid number"},
      {"<bsdf type=\"diffuse\">\n<integer name=\"a\" value=\"1.5\"/></bsdf>", 3, "1.5"},
      {"<bsdf type=\"diffuse\">\n<boolean name=\"a\" value=\"yes\"/></bsdf>", 3, "yes"},
      {"<bsdf type=\"diffuse\">\n<rgb name=\"a\" value=\"1 2\"/></bsdf>", 3, "1 or 3 values"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\"/></bsdf>", 3, "'value'"},
      {"<bsdf type=\"diffuse\">\n<float value=\"1\"/></bsdf>", 3, "'name'"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"1\" valeu=\"2\"/></bsdf>", 3, "'valeu'"},
      {"<bsdf>\n</bsdf>", 2, "'type'"},
      {"<shape type=\"obj\">\n<transform name=\"to_world\">\n<matrix value=\"1 2 3\"/></transform></shape>", 4, "16 values"},
      {"<shape type=\"obj\">\n<transform name=\"to_world\">\n<scale value=\"0\"/></transform></shape>", 3, "singular"},
      {"<shape type=\"obj\">\n<transform name=\"to_world\">\n<rotate angle=\"30\"/></transform></shape>", 4, "axis"},
      {"<shape type=\"obj\">\n<transform name=\"to_world\">\n<lookat origin=\"0 0 0\" target=\"0 0 0\"/></transform></shape>", 4, "lookat"},
      {"<shape type=\"obj\">\n<transform name=\"to_world\">\n<shear x=\"1\"/></transform></shape>", 4, "shear"},
      {"<shape type=\"obj\">\n\n<frobnicate/></shape>", 4, "unknown element <frobnicate>"},
      {"<bsdf type=\"diffuse\">\n<float name=\"a\" value=\"1\"/>\n<float name=\"a\" value=\"2\"/></bsdf>", 4, "twice"},
      {"<bsdf type=\"diffuse\">\n<spectrum name=\"a\" value=\"500:1, 400:2\"/></bsdf>", 3, "increasing"},
      {"<bsdf type=\"diffuse\">\n<blackbody name=\"a\" temperature=\"-5K\"/></bsdf>", 3, "temperature"},
      {"<bsdf type=\"diffuse\">\n<default name=\"a\" value=\"1\"/></bsdf>", 3, "<default>"},
      {"\n<ref id=\"x\"/>", 3, "<ref>"},
  };
  for (const auto& c : cases) {
    std::string msg = scene_error_of([&] { parse(c.body); });
    EXPECT_NE(msg.find("test.xml:" + std::to_string(c.line) + ":"), std::string::npos) << c.body << "\n-> " << msg;
    EXPECT_NE(msg.find(c.words), std::string::npos) << c.body << "\n-> " << msg;
  }
}

TEST(XmlParser, MalformedXmlNamesLine) {
  std::string msg = scene_error_of([] {
    parse_scene_string("<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\">\n\n</scene>\n", "dir/broken.xml");
  });
  EXPECT_NE(msg.find("dir/broken.xml:4"), std::string::npos) << msg;
  EXPECT_NE(msg.find("malformed XML"), std::string::npos) << msg;
  msg = scene_error_of([] { parse_scene_string("<scene>\n</scene>", "x.xml"); });
  EXPECT_NE(msg.find("version"), std::string::npos) << msg;
  msg = scene_error_of([] { parse_scene_string("<scene version=\"3.0.0\"/>\n<scene version=\"3.0.0\"/>", "x.xml"); });
  EXPECT_NE(msg.find("x.xml:2"), std::string::npos) << msg;
  msg = scene_error_of([] { parse_scene_string("", "empty.xml"); });
  EXPECT_NE(msg.find("empty.xml"), std::string::npos) << msg;
  msg = scene_error_of([] { parse_scene_file("/nonexistent/dir/scene.xml"); });
  EXPECT_NE(msg.find("/nonexistent/dir/scene.xml"), std::string::npos) << msg;
}

TEST(XmlParser, UnsupportedErrorListsEveryItem) {
  UnsupportedError e({{FileLoc{"s.xml", 3}, "bsdf 'roughplastic'", "diffuse 0.5"},
                      {FileLoc{"s.xml", 9}, "parameter 'alpha' of bsdf 'diffuse'", "ignored"}});
  std::string msg = e.what();
  EXPECT_NE(msg.find("\ns.xml:3: bsdf 'roughplastic' (fallback: diffuse 0.5)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("\ns.xml:9: parameter 'alpha' of bsdf 'diffuse' (fallback: ignored)"), std::string::npos)
      << msg;
  EXPECT_EQ(e.items().size(), 2u);
}

class RealScene : public ::testing::TestWithParam<const char*> {};

TEST_P(RealScene, Parses) {
  std::string path = test::shared_path(std::string("scenes/") + GetParam() + "/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  SceneDesc d = parse_scene_file(path);
  ASSERT_NE(d.root, nullptr);
  EXPECT_EQ(d.version_major, 0);
  EXPECT_FALSE(d.root->children.empty());
  size_t shapes = d.root->children_with_tag("shape").size();
  EXPECT_GT(shapes, 0u);
  for (const auto& c : d.root->children) {
    EXPECT_GT(c->loc.line, 0);
    EXPECT_EQ(c->loc.file, path);
  }
}

INSTANTIATE_TEST_SUITE_P(Shared, RealScene,
                         ::testing::Values("cornell-box", "veach-mis", "veach-bidir", "living-room", "bathroom",
                                           "staircase2", "kitchenette"));

TEST(XmlParser, RealSceneDetails) {
  std::string path = test::shared_path("scenes/kitchenette/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  SceneDesc d = parse_scene_file(path);
  auto sensors = d.root->children_with_tag("sensor");
  ASSERT_EQ(sensors.size(), 1u);
  EXPECT_EQ(sensors[0]->get_string("fov_axis", ""), "x");
  auto sampler = sensors[0]->children_with_tag("sampler");
  ASSERT_EQ(sampler.size(), 1u);
  EXPECT_EQ(sampler[0]->get_int("sample_count", 0), 64);  // from <default name="spp">
  ParseOptions opt;
  opt.defines["spp"] = "8";
  SceneDesc d2 = parse_scene_file(path, opt);
  EXPECT_EQ(d2.root->children_with_tag("sensor")[0]->children_with_tag("sampler")[0]->get_int("sample_count", 0), 8);

  std::string bathroom = test::shared_path("scenes/bathroom/scene.xml");
  TESSERA_REQUIRE_FILE(bathroom);
  SceneDesc b = parse_scene_file(bathroom);
  // The bump maps' ids sit on their inner BSDFs, which shapes reference directly.
  size_t bumpmaps = 0;
  for (const auto& c : b.root->children)
    if (c->tag == "bsdf" && c->type == "bumpmap") ++bumpmaps;
  EXPECT_EQ(bumpmaps, 2u);
}

}  // namespace
}  // namespace tessera
