// The sensor with its film, reconstruction filter and sampler, following
// Mitsuba 0.6/3 parameter names and defaults.
#include "tessera/scene/load_context.h"

#include "scene/builder_internal.h"

#include <cctype>
#include <cmath>

namespace tessera::detail {

// sensor_camera.cpp: sensor types and their cameras.
bool is_supported_sensor(const std::string& type);
bool sensor_has_fov(const std::string& type);
std::unique_ptr<Camera> make_sensor_camera(LoadContext& ctx, const SceneNode& sensor, const Transform& to_world,
                                           float fov_x, const FilmSettings& film, float near_clip, float far_clip);

int64_t get_int_in(const SceneNode& node, const std::string& name, int64_t def, int64_t lo, int64_t hi) {
  int64_t v = node.get_int(name, def);
  if (v < lo || v > hi)
    throw SceneError(node.loc_of(name), "'" + name + "' of " + node.describe() + " must be in [" + std::to_string(lo) +
                                            ", " + std::to_string(hi) + "], got " + std::to_string(v));
  return v;
}

void report_extras(BuildState& st, const std::vector<std::shared_ptr<SceneNode>>& nodes, const char* what) {
  for (size_t i = 1; i < nodes.size(); ++i) {
    st.ctx.unsupported(nodes[i]->loc, "additional " + nodes[i]->describe(), std::string("ignored (the first ") + what +
                                                                                " is used)");
    st.reported.insert(nodes[i].get());
  }
}

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr int64_t kMaxFilmSize = 1 << 15;   // pixels per side; keeps width*height well inside int
constexpr int64_t kMaxSamples = 1 << 24;    // per pixel

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// The one child with `tag`, or null; more than one is an error.
std::shared_ptr<SceneNode> single_child(const SceneNode& node, const char* tag) {
  auto list = node.children_with_tag(tag);
  if (list.size() > 1) throw SceneError(list[1]->loc, node.describe() + " has more than one <" + std::string(tag) + ">");
  return list.empty() ? nullptr : list[0];
}

std::shared_ptr<const Filter> build_filter(BuildState& st, const SceneNode* film) {
  std::shared_ptr<SceneNode> node = film ? single_child(*film, "rfilter") : nullptr;
  if (!node) return make_gaussian_filter(0.5f, 2.f);  // Mitsuba's default: gaussian, stddev 0.5
  node->used = true;
  auto radius = [&](float def) {
    float r = node->get_float("radius", def);
    if (!(r > 0.f) || r > 100.f) throw SceneError(node->loc_of("radius"), "filter radius must be in (0, 100]");
    return r;
  };
  if (node->type == "box") return make_box_filter(radius(0.5f));
  if (node->type == "tent") return make_tent_filter(radius(1.f));
  if (node->type == "gaussian") {
    float stddev = node->get_float("stddev", 0.5f);
    if (!(stddev > 0.f) || stddev > 25.f) throw SceneError(node->loc_of("stddev"), "stddev must be in (0, 25]");
    return make_gaussian_filter(stddev, 4.f * stddev);  // Mitsuba truncates at 4 standard deviations
  }
  st.ctx.unsupported(node->loc, node->describe(), fallback_for(*node));
  st.reported.insert(node.get());
  return make_gaussian_filter(0.5f, 2.f);
}

FilmSettings build_film(BuildState& st, const SceneNode* sensor) {
  FilmSettings film;
  const LoadOptions& opt = st.ctx.options();
  std::shared_ptr<SceneNode> node = sensor ? single_child(*sensor, "film") : nullptr;
  if (node) {
    node->used = true;
    if (node->type != "hdrfilm" && node->type != "ldrfilm") {
      st.ctx.unsupported(node->loc, node->describe(), fallback_for(*node));
      st.params_exempt.insert(node.get());
    }
    film.width = int(get_int_in(*node, "width", 768, 1, kMaxFilmSize));
    film.height = int(get_int_in(*node, "height", 576, 1, kMaxFilmSize));
    film.crop_x = int(get_int_in(*node, "crop_offset_x", 0, 0, film.width - 1));
    film.crop_y = int(get_int_in(*node, "crop_offset_y", 0, 0, film.height - 1));
    film.crop_width = int(get_int_in(*node, "crop_width", film.width - film.crop_x, 1, film.width - film.crop_x));
    film.crop_height = int(get_int_in(*node, "crop_height", film.height - film.crop_y, 1, film.height - film.crop_y));
    if (film.crop_x == 0 && film.crop_y == 0 && film.crop_width == film.width && film.crop_height == film.height)
      film.crop_width = film.crop_height = 0;  // whole film
    if (node->type == "ldrfilm") {
      film.ldr = true;
      film.gamma = node->get_float("gamma", -1.f);
      if (!(film.gamma == -1.f || (film.gamma > 0.f && film.gamma <= 10.f)))
        throw SceneError(node->loc_of("gamma"), "ldrfilm gamma must be -1 (sRGB) or in (0, 10]");
      film.exposure = node->get_float("exposure", 0.f);
      if (std::abs(film.exposure) > 100.f) throw SceneError(node->loc_of("exposure"), "exposure out of range");
      std::string method = lower(node->get_string("tonemap_method", "gamma"));
      if (method != "gamma")
        st.ctx.unsupported(node->loc_of("tonemap_method"), "tonemap_method '" + method + "' of " + node->describe(),
                           "gamma tonemapping");
    }
  }
  film.filter = build_filter(st, node.get());
  if (opt.width > 0 || opt.height > 0) {
    if (opt.width > kMaxFilmSize || opt.height > kMaxFilmSize) throw SceneError("film size override out of range");
    if (opt.width > 0) film.width = opt.width;
    if (opt.height > 0) film.height = opt.height;
    if (film.crop_width > 0 && (film.crop_x + film.crop_width > film.width || film.crop_y + film.crop_height > film.height)) {
      st.ctx.note(node ? node->loc : FileLoc{}, "the crop window does not fit the overridden film size; rendering the whole film");
      film.crop_x = film.crop_y = film.crop_width = film.crop_height = 0;
    }
  }
  return film;
}

SamplerSettings build_sampler(BuildState& st, const SceneNode* sensor) {
  SamplerSettings s;
  std::shared_ptr<SceneNode> node = sensor ? single_child(*sensor, "sampler") : nullptr;
  if (node) {
    node->used = true;
    const std::string& t = node->type;
    if (t == "independent") {
      s.type = SamplerType::Independent;
    } else if (t == "sobol" || t == "ldsampler" || t == "halton" || t == "hammersley" || t == "stratified" ||
               t == "multijitter" || t == "orthogonal") {
      s.type = SamplerType::Sobol;  // every low-discrepancy sampler: same expectation, different noise
    } else {
      st.ctx.unsupported(node->loc, node->describe(), fallback_for(*node));
      st.params_exempt.insert(node.get());
      s.type = SamplerType::Independent;
    }
    s.sample_count = int(get_int_in(*node, "sample_count", 4, 1, kMaxSamples));
  } else {
    s.type = SamplerType::Independent;  // Mitsuba's default sampler
  }
  if (st.ctx.options().spp > 0) {
    if (st.ctx.options().spp > kMaxSamples) throw SceneError("spp override out of range");
    s.sample_count = st.ctx.options().spp;
  }
  return s;
}

double deg(double rad) { return rad * 180.0 / kPiD; }
double rad(double deg) { return deg * kPiD / 180.0; }

/// Horizontal field of view from Mitsuba's fov/fov_axis or focal_length.
float horizontal_fov(const SceneNode& sensor, double aspect) {
  if (sensor.has("fov") && sensor.has("focal_length"))
    throw SceneError(sensor.loc, sensor.describe() + ": give either 'fov' or 'focal_length', not both");
  double fov;
  std::string axis;
  FileLoc loc = sensor.loc;
  if (sensor.has("fov")) {
    fov = sensor.get_float("fov", 0.f);
    loc = sensor.loc_of("fov");
    axis = lower(sensor.get_string("fov_axis", "x"));
  } else {
    // 35 mm film equivalent focal length, "50mm" by default; it fixes the diagonal.
    double f = 50.0;
    if (const Property* p = sensor.find("focal_length")) {
      loc = p->loc;
      if (p->type == PropType::String) {
        std::string s = sensor.get_string("focal_length", "50mm");
        if (s.size() > 2 && s.substr(s.size() - 2) == "mm") s.resize(s.size() - 2);
        char* end = nullptr;
        f = std::strtod(s.c_str(), &end);
        if (s.empty() || *end != '\0') throw SceneError(loc, "invalid focal_length '" + p->s + "'");
      } else {
        f = sensor.get_float("focal_length", 50.f);
      }
    }
    if (!(f > 0) || !std::isfinite(f)) throw SceneError(loc, "focal_length must be positive");
    fov = deg(2.0 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * f)));
    axis = "diagonal";
  }
  if (!(fov > 0 && fov < 180)) throw SceneError(loc, "field of view must be in (0, 180) degrees");
  double t = std::tan(0.5 * rad(fov)), tx;
  if (axis == "smaller") axis = aspect > 1 ? "y" : "x";
  if (axis == "larger") axis = aspect > 1 ? "x" : "y";
  if (axis == "x")
    tx = t;
  else if (axis == "y")
    tx = t * aspect;
  else if (axis == "diagonal")
    tx = t / std::sqrt(1.0 + 1.0 / (aspect * aspect));
  else
    throw SceneError(sensor.loc_of("fov_axis"), "fov_axis must be x, y, diagonal, smaller or larger, not '" + axis + "'");
  return float(deg(2.0 * std::atan(tx)));
}

/// Mitsuba 3's camera for a scene without a sensor: 45 degrees, looking along +z at the bounds.
void default_camera(BuildState& st) {
  Bounds3 b;
  std::vector<Bounds3> groups;
  for (const auto& s : st.scene.shapes) {
    if (s->group == Shape::kNoGroup) {
      b.extend(s->bounds());
      continue;
    }
    if (groups.size() <= s->group) groups.resize(s->group + 1);
    groups[s->group].extend(s->bounds());
  }
  for (const ShapeInstance& in : st.scene.instances)
    if (in.group < groups.size() && !groups[in.group].empty())
      b.extend(in.world_from_object.at(st.scene.shutter_open).apply(groups[in.group]));
  Transform xf;
  float near_clip = 1e-2f, far_clip = 1e4f;
  if (!b.empty() && is_finite(b.lo) && is_finite(b.hi)) {
    Vec3 ext = b.diagonal();
    float m = max_component(ext);
    float distance = m / (2.f * std::tan(float(rad(22.5))));
    if (m > 0.f) {
      far_clip = m * 5.f + distance;
      near_clip = distance / 100.f;
    }
    Vec3 c = b.center();
    xf = Transform::translate(Vec3(c.x, c.y, b.lo.z - distance));
  }
  st.scene.camera = make_perspective_camera(xf, 45.f, st.scene.film.width, st.scene.film.height, near_clip, far_clip);
  st.ctx.warn(st.desc.root->loc, "the scene has no sensor: using a 45-degree perspective camera fitted to the scene");
}

}  // namespace

void read_shutter(BuildState& st) {
  auto sensors = st.desc.root->children_with_tag("sensor");
  if (sensors.empty()) return;
  const SceneNode& sensor = *sensors[0];
  // Mitsuba 0.6: both default to 0 (no motion blur); scene time is in the keyframes' units.
  const float open = sensor.get_float("shutter_open", 0.f), close = sensor.get_float("shutter_close", open);
  if (!std::isfinite(open) || !std::isfinite(close))
    throw SceneError(sensor.loc_of("shutter_open"), "shutter times must be finite");
  if (close < open)
    throw SceneError(sensor.loc_of("shutter_close"), "shutter_close must not be before shutter_open");
  st.scene.shutter_open = open;
  st.scene.shutter_close = close;
}

void build_sensor(BuildState& st) {
  auto sensors = st.desc.root->children_with_tag("sensor");
  report_extras(st, sensors, "sensor");
  const SceneNode* sensor = sensors.empty() ? nullptr : sensors[0].get();
  st.scene.film = build_film(st, sensor);
  st.scene.sampler = build_sampler(st, sensor);
  if (!sensor) {
    default_camera(st);
    return;
  }
  sensor->used = true;
  if (!is_supported_sensor(sensor->type)) {
    st.ctx.unsupported(sensor->loc, sensor->describe(), fallback_for(*sensor));
    st.params_exempt.insert(sensor);
  }
  const FilmSettings& film = st.scene.film;
  const bool has_fov = sensor_has_fov(sensor->type);
  float fov_x = has_fov ? horizontal_fov(*sensor, double(film.width) / double(film.height)) : 0.f;
  if (has_fov && !(fov_x > 0.f && fov_x < 180.f))
    throw SceneError(sensor->loc, "the field of view degenerates at this aspect ratio");
  float near_clip = sensor->get_float("near_clip", 1e-2f), far_clip = sensor->get_float("far_clip", 1e4f);
  if (!(near_clip > 0.f) || !(far_clip > near_clip))
    throw SceneError(sensor->loc_of("near_clip"), "clip distances must satisfy 0 < near_clip < far_clip");
  // An animated camera is built at shutter open and moved per ray; without a shutter interval (or
  // with equal keyframes) it stands still there, as animated shapes do.
  const AnimatedTransform motion = sensor->get_animated_transform("to_world", Transform());
  const Transform to_world = motion.at(st.scene.shutter_open);
  st.scene.camera = make_sensor_camera(st.ctx, *sensor, to_world, fov_x, film, near_clip, far_clip);
  if (!motion.is_static() && st.scene.shutter_close > st.scene.shutter_open)
    st.scene.camera = make_animated_camera(std::move(st.scene.camera), to_world, motion);
}

}  // namespace tessera::detail
