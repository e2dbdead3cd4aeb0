// Participating media in a scene description: which shapes bound which media, the medium the
// camera sits in, and whether the integrator will see them.
//
// Mitsuba attaches media by name: <medium name="interior"> / <medium name="exterior"> inside a
// shape (or a <ref> to a top-level medium), and an unnamed medium inside the sensor. A shape that
// bounds a medium and has no BSDF of its own gets the `null` BSDF, as in Mitsuba: an index-matched
// boundary the light crosses unchanged.
#include "tessera/scene/load_context.h"

#include "scene/builder_internal.h"

namespace tessera::detail {

ShapeMedia build_shape_media(BuildState& st, const SceneNode& shape) {
  ShapeMedia out;
  bool seen[2] = {false, false};
  for (size_t i = 0; i < shape.children.size(); ++i) {
    const auto& child = shape.children[i];
    if (child->tag != "medium") continue;
    const std::string name = i < shape.child_names.size() ? shape.child_names[i] : std::string();
    const Medium** slot = name == "interior" ? &out.interior : name == "exterior" ? &out.exterior : nullptr;
    if (!slot)
      throw SceneError(child->loc, child->describe() + " in " + shape.describe() +
                                       " needs name=\"interior\" or name=\"exterior\"" +
                                       (name.empty() ? std::string() : ", not '" + name + "'"));
    bool& dup = seen[slot == &out.interior ? 0 : 1];
    if (dup)
      throw SceneError(child->loc, shape.describe() + " has more than one " + name + " medium");
    *slot = st.ctx.medium(child);
    dup = true;
    out.any = true;
  }
  return out;
}

void finish_media(BuildState& st) {
  Scene& scene = st.scene;
  for (const auto& sensor : st.desc.root->children_with_tag("sensor")) {
    auto media = sensor->children_with_tag("medium");
    if (media.size() > 1) throw SceneError(media[1]->loc, sensor->describe() + " has more than one medium");
    if (!media.empty()) scene.camera_medium = st.ctx.medium(media[0]);
    break;  // the first sensor is the camera (the others are reported by the sensor builder)
  }
  // Media the renderer can use (an unsupported one is reported, and stands for vacuum).
  bool media = scene.camera_medium != nullptr;
  for (const auto& s : scene.shapes) media = media || s->interior || s->exterior;

  IntegratorSettings& integrator = scene.integrator;
  auto nodes = st.desc.root->children_with_tag("integrator");
  FileLoc loc = nodes.empty() ? st.desc.root->loc : nodes[0]->loc;
  const bool surfaces_only = is_bidirectional(integrator.type) || uses_light_vertex_passes(integrator.type);
  if (integrator.type == IntegratorType::VolPath && !media) {
    integrator.type = IntegratorType::Path;  // the same estimator; no medium dimensions to draw
  } else if (surfaces_only && media) {
    // Bdpt, Ptracer and Sppm trace surfaces only; volpath converges to the image they were asked for.
    st.ctx.note(loc, std::string("the '") + integrator_name(integrator.type) +
                         "' integrator does not render participating media (volumetric light paths are not built): "
                         "this scene, which has media, is rendered by 'volpath' (the same expected image)");
    integrator.type = IntegratorType::VolPath;
  } else if (integrator.type != IntegratorType::VolPath && media) {
    st.ctx.warn(loc, std::string("the '") + integrator_name(integrator.type) +
                         "' integrator ignores the participating media of this scene (use volpath to render them)");
  }
}

}  // namespace tessera::detail
