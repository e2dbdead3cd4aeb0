// Internal to the scene builder: state shared by its parts (scene_builder.cpp builds shapes and
// lights, sensor_builder.cpp the integrator/camera/film/sampler, unsupported_report.cpp walks the
// description afterwards and reports whatever was not consumed).
#pragma once

#include "tessera/scene/load_context.h"

#include <set>

namespace tessera::detail {

struct BuildState {
  LoadContext& ctx;
  const SceneDesc& desc;
  Scene& scene;
  /// Nodes a builder already reported (or deliberately dropped): the final walk skips them whole.
  std::set<const SceneNode*> reported;
  /// Nodes whose own parameters are not checked (e.g. an unsupported sensor read as a pinhole
  /// camera), though their children are.
  std::set<const SceneNode*> params_exempt;
  /// > 0: samples per pixel an integrator's own budget asks for (guided_path), over the sampler's.
  int spp_budget = 0;
};

/// The <integrator> into scene.integrator (integrator_builder.cpp).
void build_integrator(BuildState& st);
/// A `guided_path` integrator's guiding parameters (guided_path_builder.cpp).
void read_guided_path(BuildState& st, const SceneNode& node);
/// After finish_media: bdpt and ptracer refuse a sensor they cannot importance-sample.
void check_integrator_sensor(BuildState& st);
void build_sensor(BuildState& st);  // after the shapes: a missing sensor is fitted to the scene bounds
void build_shapes(BuildState& st);
// The sensor's shutterOpen/shutterClose into scene.shutter_*: before the shapes, which move over it.
void read_shutter(BuildState& st);
void build_emitters(BuildState& st);
void report_unsupported(BuildState& st);

/// The media a shape declares with <medium name="interior|exterior"> (nested or referenced).
struct ShapeMedia {
  const Medium* interior = nullptr;
  const Medium* exterior = nullptr;
  bool any = false;  // at least one was declared (the shape is a medium boundary)
};
ShapeMedia build_shape_media(BuildState& st, const SceneNode& shape);
/// After shapes and sensor: the camera's medium, and the integrator against the media present
/// (volpath without media is path; path with media ignores them, with one warning; bdpt and ptracer
/// with media are volpath, with a note).
void finish_media(BuildState& st);

/// An integer parameter in [lo, hi]; outside it, a SceneError at the parameter's file and line.
int64_t get_int_in(const SceneNode& node, const std::string& name, int64_t def, int64_t lo, int64_t hi);
/// Every node after the first of a kind the scene may have once (sensor, integrator): reported.
void report_extras(BuildState& st, const std::vector<std::shared_ptr<SceneNode>>& nodes, const char* what);
/// The name a parameter of a Mitsuba 0.6 plugin goes by in `node`: 0.x files reach us as snake_case
/// (maxDepth as max_depth), a 2.x/3.x file keeps the name as written, so either may be there.
std::string name_in(const SceneNode& node, const std::string& snake, const std::string& camel);

/// What --allow-unsupported substitutes for an unsupported plugin node.
std::string fallback_for(const SceneNode& node);
/// The constant an unsupported texture is replaced by (its mean where known, else 0.5 grey).
Rgb texture_fallback_value(const SceneNode& node);

}  // namespace tessera::detail
