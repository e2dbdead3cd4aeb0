// The <integrator>: which of Tessera's integrators renders the scene, with its parameters under
// Mitsuba 0.6's and 3's names, and the check that needs the sensor (bdpt and ptracer connect light
// vertices to the camera, so they need one they can importance-sample).
#include "tessera/scene/load_context.h"

#include "scene/builder_internal.h"
#include "tessera/render/sppm.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <optional>

namespace tessera::detail {
namespace {

constexpr int64_t kDepthLimit = 1 << 20;

struct NamedIntegrator {
  const char* name;
  IntegratorType type;
};

// The integrators Tessera has, by the names scenes and --integrator use.
constexpr NamedIntegrator kOwn[] = {{"path", IntegratorType::Path},       {"volpath", IntegratorType::VolPath},
                                    {"direct", IntegratorType::Direct},   {"bdpt", IntegratorType::Bdpt},
                                    {"ptracer", IntegratorType::Ptracer}, {"sppm", IntegratorType::Sppm},
                                    {"vcm", IntegratorType::Vcm}};

std::optional<IntegratorType> own_type(const std::string& name) {
  for (const NamedIntegrator& n : kOwn)
    if (name == n.name) return n.type;
  return std::nullopt;
}

/// "path, volpath, direct, bdpt, ptracer, sppm or vcm"
std::string own_names() {
  std::string out;
  const size_t count = std::size(kOwn);
  for (size_t i = 0; i < count; ++i) out += std::string(i == 0 ? "" : i + 1 == count ? " or " : ", ") + kOwn[i].name;
  return out;
}

// Mitsuba integrators Tessera does not implement whose image a path tracer converges to as well
// (except for paths it cannot sample): rendered by the (volume) path tracer with a note.
bool substituted_by_path_tracer(const std::string& type) {
  static const char* const kTypes[] = {"pssmlt", "mlt", "erpt", "ppm", "photonmapper", "vpl"};
  for (const char* t : kTypes)
    if (type == t) return true;
  return false;
}

void read_depths(const SceneNode& node, IntegratorSettings& s, const std::string& max_name, const std::string& rr_name) {
  s.max_depth = int(get_int_in(node, max_name, -1, -1, kDepthLimit));
  s.rr_depth = int(get_int_in(node, rr_name, 5, 1, kDepthLimit));
}

/// path and volpath (and what they stand in for): Mitsuba 3's names, which 0.x's normalise to.
void read_path(const SceneNode& node, IntegratorSettings& s) {
  s.hide_emitters = node.get_bool("hide_emitters", false);
  s.strict_normals = node.get_bool("strict_normals", false);
  read_depths(node, s, "max_depth", "rr_depth");
}

void read_direct(const SceneNode& node, IntegratorSettings& s) {
  s.hide_emitters = node.get_bool("hide_emitters", false);
  s.strict_normals = node.get_bool("strict_normals", false);
  int shading = int(get_int_in(node, "shading_samples", 1, 0, 1 << 16));
  s.emitter_samples = int(get_int_in(node, "emitter_samples", shading, 0, 1 << 16));
  s.bsdf_samples = int(get_int_in(node, "bsdf_samples", shading, 0, 1 << 16));
  if (s.emitter_samples + s.bsdf_samples == 0)
    throw SceneError(node.loc, "the direct integrator needs emitter_samples or bsdf_samples > 0");
}

// bdpt exists only in Mitsuba 0.6, so a 2.x/3.x file may spell its parameters either way.
void read_bdpt(const SceneNode& node, IntegratorSettings& s) {
  read_depths(node, s, name_in(node, "max_depth", "maxDepth"), name_in(node, "rr_depth", "rrDepth"));
  s.light_image = node.get_bool(name_in(node, "light_image", "lightImage"), true);
  s.sample_direct = node.get_bool(name_in(node, "sample_direct", "sampleDirect"), true);
}

// How many units Mitsuba cuts its work into (0.6's granularity, 3's samples_per_pass): scheduling
// only; the image does not depend on it. Read always, so that a wrong type is an error.
void note_scheduling(BuildState& st, const SceneNode& node, const std::string& name) {
  (void)node.get_int(name, -1);
  if (const Property* p = node.peek(name))
    st.ctx.note(p->loc, "parameter '" + p->written_name + "' of " + node.describe() +
                            " only sets how Mitsuba schedules its work; ignored (the image does not depend on it)");
}

// A float parameter in [lo, hi] ((lo, hi] with open_lo); outside it, a SceneError at its line.
float get_float_in(const SceneNode& node, const std::string& name, float def, float lo, float hi, bool open_lo) {
  const float v = node.get_float(name, def);
  if (!(open_lo ? v > lo : v >= lo) || !(v <= hi)) {
    char range[96];
    if (std::isinf(hi)) std::snprintf(range, sizeof range, "%s %g", open_lo ? ">" : ">=", double(lo));
    else std::snprintf(range, sizeof range, "in %s%g, %g]", open_lo ? "(" : "[", double(lo), double(hi));
    throw SceneError(node.loc_of(name), "'" + node.peek(name)->written_name + "' of " + node.describe() + " must be " +
                                            range + ", got " + std::to_string(v));
  }
  return v;
}

// ptracer: Mitsuba 0.6's maxDepth, rrDepth, granularity, bruteForce and Mitsuba 3's max_depth,
// rr_depth, hide_emitters, samples_per_pass.
void read_ptracer(BuildState& st, const SceneNode& node, IntegratorSettings& s) {
  read_depths(node, s, name_in(node, "max_depth", "maxDepth"), name_in(node, "rr_depth", "rrDepth"));
  s.hide_emitters = node.get_bool(name_in(node, "hide_emitters", "hideEmitters"), false);
  for (const std::string& name : {std::string("granularity"), name_in(node, "samples_per_pass", "samplesPerPass")})
    note_scheduling(st, node, name);
  // bruteForce leaves out the connections to the camera (a debugging mode); false is what Tessera does.
  const std::string brute = name_in(node, "brute_force", "bruteForce");
  if (node.get_bool(brute, false))
    st.ctx.unsupported(node.loc_of(brute), "parameter '" + node.peek(brute)->written_name + "' of " + node.describe(),
                       "false (every light vertex is connected to the camera)");
}

// sppm: Mitsuba 0.6's maxDepth, rrDepth (default 3), photonCount, initialRadius, alpha, maxPasses,
// granularity, under either spelling.
void read_sppm(BuildState& st, const SceneNode& node, IntegratorSettings& s) {
  read_depths(node, s, name_in(node, "max_depth", "maxDepth"), name_in(node, "rr_depth", "rrDepth"));
  if (!node.peek(name_in(node, "rr_depth", "rrDepth"))) s.rr_depth = 3;
  const std::string count = name_in(node, "photon_count", "photonCount");
  const int64_t photons = node.get_int(count, 250000);
  if (photons < 1 || uint64_t(photons) > kMaxPhotonsPerPass)
    throw SceneError(node.loc_of(count), "'" + node.peek(count)->written_name + "' of " + node.describe() + " is " +
                                             std::to_string(photons) + ": a pass's photon map holds 1 to " +
                                             std::to_string(kMaxPhotonsPerPass) + " photons (its cap of " +
                                             std::to_string(kMaxPhotonMapBytes >> 20) + " MiB at 32 bytes a photon)");
  s.photon_count = uint64_t(photons);
  s.initial_radius = get_float_in(node, name_in(node, "initial_radius", "initialRadius"), 0.f, 0.f, kInfinity, false);
  s.alpha = get_float_in(node, "alpha", 0.7f, 0.f, 1.f, true);
  const std::string passes = name_in(node, "max_passes", "maxPasses");
  s.max_passes = int(get_int_in(node, passes, -1, -1, INT32_MAX));
  if (s.max_passes == 0)
    throw SceneError(node.loc_of(passes), "'" + passes + "' of " + node.describe() +
                                              " must be -1 (no limit) or at least 1, got 0");
  note_scheduling(st, node, "granularity");
}

// vcm, Tessera's own (Mitsuba has none): bdpt's depths and switches, sppm's radius and alpha
// (default 0.75, SmallVCM's), merge and connect.
void read_vcm(const SceneNode& node, IntegratorSettings& s) {
  read_bdpt(node, s);
  s.initial_radius = get_float_in(node, "initial_radius", 0.f, 0.f, kInfinity, false);
  s.alpha = get_float_in(node, "alpha", 0.75f, 0.f, 1.f, true);
  s.merge = node.get_bool("merge", true);
  s.connect = node.get_bool("connect", true);
  s.merge_roughness = get_float_in(node, "merge_roughness", s.merge_roughness, 0.f, 1.f, false);
  s.merge_direct = node.get_bool("merge_direct", s.merge_direct);
  if (!s.merge && !s.connect)
    throw SceneError(node.loc, node.describe() + " with neither merge nor connect has no strategy to render with");
}

// An integrator given on the command line in place of one that traces paths of a bounded depth
// keeps that depth: the same light paths, by another method (what comparisons of methods need).
bool keep_depths(const SceneNode& node, IntegratorSettings& s) {
  static const char* const kTracers[] = {"path", "volpath", "guided_path", "bdpt", "ptracer", "sppm", "vcm"};
  if (std::none_of(std::begin(kTracers), std::end(kTracers), [&](const char* t) { return node.type == t; }) &&
      !substituted_by_path_tracer(node.type))
    return false;
  read_depths(node, s, name_in(node, "max_depth", "maxDepth"), name_in(node, "rr_depth", "rrDepth"));
  return true;
}

void read_parameters(BuildState& st, const SceneNode& node, IntegratorSettings& s) {
  switch (s.type) {
    case IntegratorType::Direct: read_direct(node, s); break;
    case IntegratorType::Bdpt: read_bdpt(node, s); break;
    case IntegratorType::Ptracer: read_ptracer(st, node, s); break;
    case IntegratorType::Sppm: read_sppm(st, node, s); break;
    case IntegratorType::Vcm: read_vcm(node, s); break;
    case IntegratorType::Path:
    case IntegratorType::VolPath: read_path(node, s); break;
  }
}

}  // namespace

void build_integrator(BuildState& st) {
  auto nodes = st.desc.root->children_with_tag("integrator");
  report_extras(st, nodes, "integrator");
  const SceneNode* node = nodes.empty() ? nullptr : nodes[0].get();
  const std::string& override_type = st.ctx.options().integrator;
  // Mitsuba 0.x falls back to `direct` without an <integrator>; Mitsuba 2/3 to `path`.
  std::string type = node ? node->type : (st.desc.version_major < 2 ? "direct" : "path");
  IntegratorSettings& s = st.scene.integrator;
  if (!override_type.empty()) {
    if (!own_type(override_type)) throw SceneError("unknown integrator '" + override_type + "' (use " + own_names() + ")");
    if (node && node->type != override_type) {
      const bool depths = keep_depths(*node, s);
      st.ctx.note(node->loc, node->describe() + " replaced by the '" + override_type +
                                 "' integrator given on the command line; " +
                                 (depths ? "it keeps its maximum and Russian roulette depths, its other parameters are ignored"
                                         : "its parameters are ignored"));
      st.reported.insert(node);
      node = nullptr;
    }
    type = override_type;
  }
  if (node) node->used = true;
  if (const std::optional<IntegratorType> own = own_type(type)) {
    s.type = *own;  // volpath: finish_media() makes it path when there are no media
    if (node) read_parameters(st, *node, s);
    else if (s.type == IntegratorType::Sppm && nodes.empty()) s.rr_depth = 3;  // (Mitsuba's sppm's default)
  } else if (type == "guided_path") {
    s.type = IntegratorType::Path;  // (the plugin is a surface path tracer)
    read_guided_path(st, *node);
    read_path(*node, s);
  } else if (substituted_by_path_tracer(type)) {
    st.ctx.note(node->loc, node->describe() + " is rendered by Tessera's path tracer (volpath where the scene has media): "
                               "the same expected image, except for light paths a path tracer cannot sample, "
                               "such as caustics of point lights seen through specular surfaces");
    st.params_exempt.insert(node);  // its own parameters (photon counts, mutations...) mean nothing here
    s.type = IntegratorType::VolPath;
    read_path(*node, s);
  } else {
    st.ctx.unsupported(node->loc, node->describe(), fallback_for(*node));
    st.reported.insert(node);
    s.type = IntegratorType::VolPath;
  }
}

void check_integrator_sensor(BuildState& st) {
  const IntegratorType type = st.scene.integrator.type;
  if (!is_bidirectional(type)) return;
  auto sensors = st.desc.root->children_with_tag("sensor");
  if (sensors.empty()) return;  // the camera fitted to the scene is a perspective one
  const SceneNode& sensor = *sensors[0];
  if (sensor.type == "perspective" || sensor.type == "thinlens") return;
  throw SceneError(sensor.loc, std::string("the ") + integrator_name(type) +
                                   " integrator needs a sensor it can importance-sample (perspective or thinlens); "
                                   "this scene's is " + sensor.describe() +
                                   " (render it with path or volpath, e.g. --integrator path)");
}

}  // namespace tessera::detail

namespace tessera {

const char* integrator_name(IntegratorType type) {
  for (const detail::NamedIntegrator& n : detail::kOwn)
    if (n.type == type) return n.name;
  return "?";
}

}  // namespace tessera
