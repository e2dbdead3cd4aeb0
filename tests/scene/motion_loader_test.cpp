// <animation> keyframes, the shutter, and moving shapes in the loader.
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <string>

namespace tessera {
namespace {

std::string expect_error(const std::string& xml) {
  try {
    SceneDesc d = parse_scene_string(xml, "mem/anim.xml");
    load_scene(d, LoadOptions{});
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for " << xml;
  return "";
}

TEST(MotionLoader, AnimationKeyframesAreParsed) {
  SceneDesc d = parse_scene_string(R"(<scene version="0.6.0"><shape type="sphere">
      <animation name="toWorld">
        <transform time="0"><translate x="1"/></transform>
        <transform time="0.5"><scale value="2"/><translate x="3"/></transform>
      </animation></shape></scene>)", "mem/anim.xml");
  const SceneNode& shape = *d.root->children[0];
  const Property* p = shape.peek("to_world");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->type, PropType::Animation);
  ASSERT_EQ(p->keyframes.size(), 2u);
  EXPECT_EQ(p->keyframes[1].time, 0.5f);
  EXPECT_EQ(p->keyframes[1].xf.apply_point(Vec3(1.f, 0.f, 0.f)), Vec3(5.f, 0.f, 0.f));
  EXPECT_EQ(p->loc.line, 2);
  AnimatedTransform a = shape.get_animated_transform("to_world", Transform());
  EXPECT_FALSE(a.is_static());
  EXPECT_EQ(a.at(0.25f).apply_point(Vec3(0.f)), Vec3(2.f, 0.f, 0.f));
  // A plugin that wants a static transform is told, with the line.
  EXPECT_THROW(shape.get_transform("to_world", Transform()), SceneError);
}

TEST(MotionLoader, BadAnimationsAreErrorsWithLines) {
  std::string m = expect_error(R"(<scene version="0.6.0"><shape type="sphere">
      <animation name="toWorld"></animation></shape></scene>)");
  EXPECT_NE(m.find("mem/anim.xml:2"), std::string::npos) << m;
  EXPECT_NE(m.find("no <transform time"), std::string::npos) << m;
  m = expect_error(R"(<scene version="0.6.0"><shape type="sphere"><animation name="toWorld">
      <transform time="1"><translate x="1"/></transform>
      <transform time="0.5"><translate x="2"/></transform></animation></shape></scene>)");
  EXPECT_NE(m.find("mem/anim.xml:3"), std::string::npos) << m;
  EXPECT_NE(m.find("increase strictly"), std::string::npos) << m;
  m = expect_error(R"(<scene version="0.6.0"><shape type="sphere"><animation name="toWorld">
      <translate x="1"/></animation></shape></scene>)");
  EXPECT_NE(m.find("mem/anim.xml:2"), std::string::npos) << m;
  m = expect_error(R"(<scene version="0.6.0"><shape type="sphere"><animation name="toWorld">
      <transform><translate x="1"/></transform></animation></shape></scene>)");
  EXPECT_NE(m.find("time"), std::string::npos) << m;
  m = expect_error(R"(<scene version="0.6.0"><sensor type="perspective">
      <float name="shutterOpen" value="1"/><float name="shutterClose" value="0.5"/></sensor></scene>)");
  EXPECT_NE(m.find("mem/anim.xml:2"), std::string::npos) << m;
  // An animated sensor loads (tests/render/motion_blur_test.cpp renders one); a bad keyframe in it
  // is an error like anywhere else.
  m = expect_error(R"(<scene version="0.6.0"><sensor type="perspective"><animation name="toWorld">
      <transform time="1"/><transform time="0"><translate x="1"/></transform></animation></sensor></scene>)");
  EXPECT_NE(m.find("mem/anim.xml"), std::string::npos) << m;
}

const char* kMoving = R"(<scene version="0.6.0">
    <sensor type="perspective"><float name="shutterOpen" value="0"/><float name="shutterClose" value="%CLOSE%"/></sensor>
    <shape type="sphere"><point name="center" x="0" y="0" z="5"/><point name="centerClose" x="2" y="0" z="5"/>%EMIT%</shape>
    <shape type="cube"/></scene>)";

std::string moving(const std::string& close, const std::string& emit = "") {
  std::string s = kMoving;
  s.replace(s.find("%CLOSE%"), 7, close);
  s.replace(s.find("%EMIT%"), 6, emit);
  return s;
}

TEST(MotionLoader, MovingSphereIsPlacedByTheInstanceBvh) {
  auto scene = load_scene(parse_scene_string(moving("1"), "mem/m.xml"), LoadOptions{}).scene;
  EXPECT_EQ(scene->shutter_close, 1.f);
  ASSERT_EQ(scene->instance_accel().size(), 1u);
  const Bounds3 b = scene->placement_bounds(0);
  EXPECT_LE(b.lo.x, -1.f);
  EXPECT_GE(b.hi.x, 3.f);
  EXPECT_TRUE(scene->bounds().contains(Vec3(3.f, 0.f, 5.f)));
  Ray r;
  r.o = Vec3(2.f, 0.f, 0.f);
  r.d = Vec3(0.f, 0.f, 1.f);
  SurfaceInteraction si;
  r.time = 0.f;
  EXPECT_FALSE(scene->intersect(r, si));
  EXPECT_FALSE(scene->occluded(r));
  r.time = 1.f;
  ASSERT_TRUE(scene->intersect(r, si));
  EXPECT_NEAR(si.t, 4.f, 1e-4f);
  EXPECT_NEAR(length(si.ng - Vec3(0.f, 0.f, -1.f)), 0.f, 1e-4f);
  EXPECT_TRUE(scene->occluded(r));
  // A closed shutter: static at its shutter-open centre.
  auto still = load_scene(parse_scene_string(moving("0"), "mem/m.xml"), LoadOptions{}).scene;
  EXPECT_FALSE(still->has_motion());
  EXPECT_FALSE(still->intersect(r, si));
}

TEST(MotionLoader, EmitterOnAMovingShapeIsUnsupported) {
  const std::string xml = moving("1", R"(<emitter type="area"><rgb name="radiance" value="1"/></emitter>)");
  EXPECT_THROW(load_scene(parse_scene_string(xml, "mem/m.xml"), LoadOptions{}), UnsupportedError);
  LoadOptions o;
  o.allow_unsupported = true;
  auto r = load_scene(parse_scene_string(xml, "mem/m.xml"), o);
  ASSERT_EQ(r.unsupported.size(), 1u);
  EXPECT_TRUE(r.scene->lights.empty());
}

}  // namespace
}  // namespace tessera
