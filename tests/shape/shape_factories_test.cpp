// The shape plugins as the scene loader calls them: parameters from parsed XML, files resolved and
// cached through LoadContext.
#include "shape_test_util.h"
#include "test_support.h"

#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

using test::write_scratch;

struct Loaded {
  SceneDesc desc;
  Scene scene;
  LoadOptions options;
  std::unique_ptr<LoadContext> ctx;
  std::vector<std::shared_ptr<SceneNode>> shapes;

  explicit Loaded(const std::string& body) {
    std::string xml = "<scene version=\"0.6.0\">\n" + body + "</scene>\n";
    desc = parse_scene_string(xml, (test::scratch_dir() / "factories.xml").string());
    ctx = std::make_unique<LoadContext>(desc, options, scene);
    shapes = desc.root->children_with_tag("shape");
  }
  ShapeGeometry make(size_t i) {
    ShapeFactory f = find_shape_factory(shapes.at(i)->type);
    EXPECT_NE(f, nullptr) << shapes.at(i)->type;
    return f(*shapes.at(i), *ctx);
  }
  size_t warnings() const {
    size_t n = 0;
    for (const auto& m : ctx->messages()) n += m.level == LoadMessage::Level::Warning;
    return n;
  }
};

TEST(ShapeFactories, AllTypesAreRegistered) {
  for (const char* t : {"obj", "ply", "serialized", "rectangle", "cube", "disk", "sphere"})
    EXPECT_NE(find_shape_factory(t), nullptr) << t;
}

TEST(ShapeFactories, ObjParametersCachingAndOneDegenerateWarning) {
  write_scratch("factory.obj",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nvt 0 0.25\nf 1/1 2/1 3/1\nf 1 2 4\n");
  Loaded l(R"(
    <shape type="obj"><string name="filename" value="factory.obj"/></shape>
    <shape type="obj"><string name="filename" value="factory.obj"/>
      <boolean name="flipNormals" value="true"/></shape>
    <shape type="obj"><string name="filename" value="factory.obj"/>
      <boolean name="faceNormals" value="true"/><boolean name="flipTexCoords" value="false"/></shape>
  )");
  ShapeGeometry a = l.make(0), b = l.make(1), c = l.make(2);
  ASSERT_TRUE(a.mesh && b.mesh && c.mesh);
  EXPECT_FALSE(a.is_sphere);
  EXPECT_EQ(a.mesh, b.mesh);  // flip_normals is applied by the shape: same cached data
  EXPECT_FALSE(a.flip_normals);
  EXPECT_TRUE(b.flip_normals);
  EXPECT_NE(a.mesh, c.mesh);
  EXPECT_TRUE(c.face_normals);
  EXPECT_TRUE(c.mesh->normals.empty());
  EXPECT_FLOAT_EQ(a.mesh->uvs[0].y, 0.75f);
  EXPECT_FLOAT_EQ(c.mesh->uvs[0].y, 0.25f);
  EXPECT_EQ(a.mesh->num_triangles(), 1u);
  EXPECT_EQ(l.warnings(), 2u);  // one per distinct load, not per shape or per triangle
}

TEST(ShapeFactories, KitchenetteSerializedByShapeIndex) {
  std::string path = test::shared_path("scenes/kitchenette/meshes/kitchen.serialized");
  TESSERA_REQUIRE_FILE(path);
  Loaded l("<shape type=\"serialized\"><string name=\"filename\" value=\"" + path +
           "\"/><integer name=\"shapeIndex\" value=\"10\"/></shape>\n"
           "<shape type=\"serialized\"><string name=\"filename\" value=\"" + path +
           "\"/><integer name=\"shapeIndex\" value=\"88\"/></shape>\n");
  ShapeGeometry g = l.make(0);
  ASSERT_TRUE(g.mesh);
  EXPECT_GT(g.mesh->num_triangles(), 0u);
  EXPECT_EQ(g.mesh, l.make(0).mesh);
  test::expect_scene_error([&] { l.make(1); }, path, "out of range");
}

TEST(ShapeFactories, AnalyticShapesAndSphere) {
  Loaded l(R"(
    <shape type="rectangle"/>
    <shape type="cube"><boolean name="flipNormals" value="true"/></shape>
    <shape type="disk"/>
    <shape type="sphere"><point name="center" x="1" y="2" z="3"/>
      <float name="radius" value="0.5"/></shape>
    <shape type="sphere"><float name="radius" value="-1"/></shape>
  )");
  EXPECT_NEAR(test::mesh_area(*l.make(0).mesh), 4.0, 1e-6);
  ShapeGeometry cube = l.make(1);
  EXPECT_TRUE(cube.flip_normals);
  EXPECT_NEAR(test::mesh_area(*cube.mesh), 24.0, 1e-5);
  EXPECT_NEAR(test::mesh_area(*l.make(2).mesh), 3.14159265, 1e-5);
  ShapeGeometry s = l.make(3);
  EXPECT_TRUE(s.is_sphere);
  EXPECT_EQ(s.center, Vec3(1, 2, 3));
  EXPECT_EQ(s.radius, 0.5f);
  EXPECT_THROW(l.make(4), SceneError);
}

TEST(ShapeFactories, MissingFilesAreSceneErrors) {
  Loaded l(R"(
    <shape type="obj"><string name="filename" value="nowhere.obj"/></shape>
    <shape type="ply"/>
  )");
  try {
    l.make(0);
    ADD_FAILURE() << "expected SceneError";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("nowhere.obj"), std::string::npos) << e.what();
    EXPECT_GT(e.loc().line, 0);  // points at the XML
  }
  EXPECT_THROW(l.make(1), SceneError);
}

}  // namespace
}  // namespace tessera
