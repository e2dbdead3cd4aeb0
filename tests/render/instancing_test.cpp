// Instancing: a scene of shapegroup instances (rotated, non-uniformly scaled, mirrored) converges
// to the image of its flattened twin, where every member is written out with the composed
// transform, and renders to the same bits for any thread count and tile size.
#include "image_agreement.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace tessera {
namespace {

constexpr int kSpp = 512;

// The members, each with its own to_world inside the group. Twosided BSDFs: a mirroring placement
// turns a flattened mesh inside out (world-space winding) but not an instance (Mitsuba 3's rule),
// which only a one-sided BSDF would see.
const std::vector<std::string> kMembers = {
    R"(<shape type="cube"><ref id="red"/><transform name="to_world">%OWN%</transform></shape>)",
    R"(<shape type="sphere"><float name="radius" value="0.25"/><ref id="white"/><transform name="to_world">%OWN%</transform></shape>)",
    R"(<shape type="rectangle"><ref id="white"/><transform name="to_world">%OWN%</transform></shape>)"};
const std::vector<std::string> kOwn = {R"(<scale x="0.3" y="0.5" z="0.3"/><rotate y="1" angle="25"/>)",
                                       R"(<translate x="0.5" y="0.1" z="0.2"/>)",
                                       R"(<scale value="0.3"/><rotate x="1" angle="-60"/><translate x="-0.5" z="0.3"/>)"};
const std::vector<std::string> kPlacements = {
    R"(<rotate z="1" angle="30"/><translate x="-0.9" y="-0.3" z="0.5"/>)",
    R"(<scale x="-1" y="1" z="1"/><rotate y="1" angle="20"/><translate x="0.1" y="0.7" z="0.9"/>)",
    R"(<scale x="1.4" y="0.6" z="1"/><translate x="0.8" y="0.2" z="0.5"/>)"};
// The sphere (member 1) is a group of its own, placed only by the placements that keep it a sphere:
// a flattened sphere cannot take a non-uniform scale (an instanced one can).
constexpr size_t kSpherePlacements = 2;

std::string replace(std::string s, const std::string& what, const std::string& with) {
  return s.replace(s.find(what), what.size(), with);
}

enum class Form { Instanced, Flattened, Without };

std::string scene_xml(Form form) {
  std::string body;
  if (form == Form::Instanced) {
    body += "<shapegroup id=\"g\">" + replace(kMembers[0], "%OWN%", kOwn[0]) + replace(kMembers[2], "%OWN%", kOwn[2]) +
            "</shapegroup><shapegroup id=\"s\">" + replace(kMembers[1], "%OWN%", kOwn[1]) + "</shapegroup>";
    for (size_t p = 0; p < kPlacements.size(); ++p)
      for (const char* group : {"g", "s"})
        if (group[0] == 'g' || p < kSpherePlacements)
          body += std::string("<shape type=\"instance\"><ref id=\"") + group + "\"/><transform name=\"to_world\">" +
                  kPlacements[p] + "</transform></shape>";
  } else if (form == Form::Flattened) {
    // Mitsuba applies a transform's steps in order: the member's own, then the instance's.
    for (size_t p = 0; p < kPlacements.size(); ++p)
      for (size_t m = 0; m < kMembers.size(); ++m)
        if (m != 1 || p < kSpherePlacements) body += replace(kMembers[m], "%OWN%", kOwn[m] + kPlacements[p]);
  }
  return R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0, -4, 2.5" target="0, 0, 0.5" up="0, 0, 1"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/></film>
  </sensor>
  <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.2, 0.1"/></bsdf></bsdf>
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
  <shape type="rectangle"><ref id="white"/><transform name="to_world"><scale value="4"/></transform></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.6"/><rotate x="1" angle="180"/><translate z="3"/></transform>
    <emitter type="area"><rgb name="radiance" value="12"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
  )" + body + "</scene>";
}

Film render_xml(const std::string& xml, uint32_t seed, int threads = 2, int tile_size = 32) {
  auto scene = load_scene(parse_scene_string(xml, "mem/instancing.xml"), LoadOptions{}).scene;
  RenderSettings rs;
  rs.spp = kSpp;
  rs.seed = seed;
  rs.threads = threads;
  rs.tile_size = tile_size;
  return render(*scene, rs);
}

TEST(Instancing, ConvergesToTheFlattenedTwin) {
  const auto instanced = load_scene(parse_scene_string(scene_xml(Form::Instanced), "mem/i.xml"), LoadOptions{}).scene;
  const auto flat = load_scene(parse_scene_string(scene_xml(Form::Flattened), "mem/f.xml"), LoadOptions{}).scene;
  ASSERT_EQ(instanced->instances.size(), kPlacements.size() + kSpherePlacements);
  EXPECT_EQ(flat->instances.size(), 0u);
  EXPECT_EQ(instanced->num_instanced_triangles(), flat->num_triangles());
  const Film a = render_xml(scene_xml(Form::Instanced), 1), b = render_xml(scene_xml(Form::Flattened), 2);
  const int tests = test::expect_same_expectation(a, b, 8, 4.0, "instanced vs flattened");
  EXPECT_GT(tests, 12);
  // Not vacuous: the instances are in view and lit, and their absence would be seen.
  const Film empty = render_xml(scene_xml(Form::Without), 3);
  const test::BlockStats sa = test::block_stats(a, 8, 4, 24, 20), se = test::block_stats(empty, 8, 4, 24, 20);
  EXPECT_GT(std::abs(sa.mean[0] - se.mean[0]), 10.0 * std::sqrt(sa.se2[0] + se.se2[0]));
}

TEST(Instancing, SameBitsForAnyThreadCountAndTileSize) {
  const Film a = render_xml(scene_xml(Form::Instanced), 5, 1, 8), b = render_xml(scene_xml(Form::Instanced), 5, 2, 32);
  EXPECT_TRUE(test::same_bits(a, b));
}

}  // namespace
}  // namespace tessera
