// Environment map light; conventions and the sampling scheme are documented in light/envmap.h.
#include "tessera/light/envmap.h"

#include "light/emitter_sample.h"

#include "tessera/core/check.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace tessera {

namespace {
constexpr double kPiD = 3.14159265358979323846;
}  // namespace

Vec2 envmap_direction_to_uv(Vec3 d) {
  float u = std::atan2(d.x, -d.z) * kInv2Pi;
  if (u < 0.f) u += 1.f;
  if (u >= 1.f) u = 0.f;
  // atan2 of (sin, cos) stays accurate near the poles, where acos(d.y) loses digits.
  float theta = std::atan2(std::sqrt(d.x * d.x + d.z * d.z), d.y);
  return {u, std::clamp(theta * kInvPi, 0.f, 1.f)};
}

Vec3 envmap_uv_to_direction(Vec2 uv) {
  float phi = uv.x * 2.f * kPi, theta = uv.y * kPi;
  float sin_theta = std::sin(theta);
  return {std::sin(phi) * sin_theta, std::cos(theta), -std::cos(phi) * sin_theta};
}

EnvmapLight::EnvmapLight(const Image& radiance, float scale, const Transform& world_from_light)
    : width_(radiance.width()), height_(radiance.height()) {
  TESSERA_CHECK(width_ >= 2 && height_ >= 3);
  texels_.resize(size_t(width_) * size_t(height_));
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      Rgb v = radiance.rgb(x, y) * scale;
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(v[c])) v[c] = 0.f;
      texels_[size_t(y) * size_t(width_) + size_t(x)] = v;
    }

  // Row y lies at theta = pi y / (H - 1). Cosines in double: near the poles the cells are thin
  // and their cos(theta) extents would lose most of their digits in float.
  row_cos_.resize(size_t(height_));
  for (int y = 0; y < height_; ++y) row_cos_[size_t(y)] = std::cos(kPiD * y / (height_ - 1));
  row_cos_.front() = 1.0;
  row_cos_.back() = -1.0;
  inv_cell_solid_angle_.resize(size_t(height_ - 1));
  for (int j = 0; j + 1 < height_; ++j) {
    double dcos = row_cos_[size_t(j)] - row_cos_[size_t(j + 1)];
    // pdf_uv / ((H - 1) * 2 pi * dcos) turns the unit-square density into solid angle.
    inv_cell_solid_angle_[size_t(j)] = float(1.0 / (double(height_ - 1) * 2.0 * kPiD * dcos));
  }

  std::vector<float> weights(size_t(width_) * size_t(height_ - 1));
  weight_sum_ = 0;
  for (int j = 0; j + 1 < height_; ++j) {
    double dcos = row_cos_[size_t(j)] - row_cos_[size_t(j + 1)];
    for (int i = 0; i < width_; ++i) {
      int i1 = (i + 1) % width_;
      double lum = 0.25 * (double(std::max(texel(i, j).luminance(), 0.f)) + std::max(texel(i1, j).luminance(), 0.f) +
                           std::max(texel(i, j + 1).luminance(), 0.f) + std::max(texel(i1, j + 1).luminance(), 0.f));
      double w = lum * dcos;
      weights[size_t(j) * size_t(width_) + size_t(i)] = float(w);
      weight_sum_ += w;
    }
  }
  distribution_ = Distribution2D(weights, width_, height_ - 1);

  const auto& m = world_from_light.matrix().m;
  const auto& mi = world_from_light.inverse_matrix().m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      m_[r][c] = float(m[r][c]);
      inv_[r][c] = float(mi[r][c]);
    }
}

Vec3 EnvmapLight::to_light(Vec3 d) const {
  return normalize(Vec3(inv_[0][0] * d.x + inv_[0][1] * d.y + inv_[0][2] * d.z,
                        inv_[1][0] * d.x + inv_[1][1] * d.y + inv_[1][2] * d.z,
                        inv_[2][0] * d.x + inv_[2][1] * d.y + inv_[2][2] * d.z));
}

Vec3 EnvmapLight::to_world(Vec3 d) const {
  return normalize(Vec3(m_[0][0] * d.x + m_[0][1] * d.y + m_[0][2] * d.z,
                        m_[1][0] * d.x + m_[1][1] * d.y + m_[1][2] * d.z,
                        m_[2][0] * d.x + m_[2][1] * d.y + m_[2][2] * d.z));
}

Rgb EnvmapLight::lookup(Vec2 uv) const {
  // Mitsuba 3: shift by half a texel so that column x is centred on (x + 0.5) / W, wrap, and
  // interpolate towards column x + 1 (column W - 1 towards column 0).
  float x = uv.x - 0.5f / float(width_);
  x -= std::floor(x);
  x *= float(width_);
  int x0 = std::min(int(x), width_ - 1);
  int x1 = x0 + 1 == width_ ? 0 : x0 + 1;
  float fx = std::clamp(x - float(x0), 0.f, 1.f);
  float y = std::clamp(uv.y, 0.f, 1.f) * float(height_ - 1);
  int y0 = std::min(int(y), height_ - 2);
  float fy = std::clamp(y - float(y0), 0.f, 1.f);
  Rgb top = texel(x0, y0) * (1.f - fx) + texel(x1, y0) * fx;
  Rgb bottom = texel(x0, y0 + 1) * (1.f - fx) + texel(x1, y0 + 1) * fx;
  return top * (1.f - fy) + bottom * fy;
}

Rgb EnvmapLight::le_env(Vec3 d) const { return lookup(envmap_direction_to_uv(to_light(d))); }

float EnvmapLight::pdf_light(Vec3 d) const {
  Vec2 uv = envmap_direction_to_uv(d);
  float x = uv.x - 0.5f / float(width_);
  x -= std::floor(x);
  int i = std::min(int(x * float(width_)), width_ - 1);
  int j = std::min(int(uv.y * float(height_ - 1)), height_ - 2);
  // Row by angle, as sample_li() draws cos(theta) between the rows' cosines.
  float pdf_cell = distribution_.pdf(Vec2((float(i) + 0.5f) / float(width_), (float(j) + 0.5f) / float(height_ - 1)));
  return pdf_cell * inv_cell_solid_angle_[size_t(j)];
}

float EnvmapLight::pdf_env(Vec3 d) const { return pdf_light(to_light(d)); }

bool EnvmapLight::sample_direction(Vec2 u, Vec3& d_light, Vec2& uv, float& pdf) const {
  float pdf_cell = 0.f;
  Vec2 s = distribution_.sample(u, &pdf_cell);
  if (!(pdf_cell > 0.f)) return false;
  int j = std::min(int(s.y * float(height_ - 1)), height_ - 2);
  // Uniform in phi and in cos(theta) within the cell: constant solid-angle density.
  double ty = std::clamp(double(s.y) * (height_ - 1) - j, 0.0, 1.0);
  double cos_theta = row_cos_[size_t(j)] + ty * (row_cos_[size_t(j + 1)] - row_cos_[size_t(j)]);
  double sin_theta = std::sqrt(std::max(0.0, (1.0 - cos_theta) * (1.0 + cos_theta)));
  double u_tex = double(s.x) + 0.5 / width_;
  double phi = 2.0 * kPiD * u_tex;
  d_light = Vec3(float(std::sin(phi) * sin_theta), float(cos_theta), float(-std::cos(phi) * sin_theta));
  uv = Vec2(float(u_tex >= 1.0 ? u_tex - 1.0 : u_tex), float(std::atan2(sin_theta, cos_theta) / kPiD));
  pdf = pdf_cell * inv_cell_solid_angle_[size_t(j)];
  return true;
}

bool EnvmapLight::sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const {
  Vec3 d_light;
  Vec2 uv;
  float pdf = 0.f;
  if (!sample_direction(u, d_light, uv, pdf)) return false;
  Vec3 wi = to_world(d_light);
  float r = std::max({radius_, length(ref_p - center_), 1e-3f});
  if (out.defer_li) {
    out.li_uv = uv;
    out.li_deferred = true;
  } else {
    out.li = lookup(uv);
  }
  out.wi = wi;
  out.p_light = ref_p + wi * (2.f * r);
  out.n_light = Vec3(0.f);
  out.dist = kInfinity;
  out.pdf = pdf;
  out.delta = false;
  return out.pdf > 0.f;
}

// Emission: the direction sample_li would pick towards the map, travelling the other way, from
// the disk facing it. Density and radiance are those of pdf_env() and le_env() at the final world
// direction (not of the cell drawn), so that pdf_le() and a camera ray that escapes along it
// agree with this sample to the bit.
bool EnvmapLight::sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const {
  Vec3 d_light;
  Vec2 uv;
  float pdf = 0.f;
  if (!sample_direction(u_dir, d_light, uv, pdf)) return false;
  const Vec3 wi = to_world(d_light);
  if (!detail::EmissionDisk{center_, radius_}.sample(-wi, u_pos, out)) return false;
  out.pdf_dir = pdf_env(wi);
  out.le = le_env(wi);
  out.delta_dir = false;
  return out.pdf_dir > 0.f && !out.le.is_black();
}

void EnvmapLight::pdf_le(Vec3, Vec3, Vec3 dir, float& pdf_pos, float& pdf_dir) const {
  pdf_pos = detail::EmissionDisk{center_, radius_}.pdf_pos();
  pdf_dir = pdf_env(-dir);
}

void EnvmapLight::preprocess(const Bounds3& scene_bounds) {
  center_ = scene_bounds.empty() ? Vec3(0.f) : scene_bounds.center();
  radius_ = scene_bounds.empty() ? 0.f : 0.5f * length(scene_bounds.diagonal());
}

float EnvmapLight::power() const {
  float r = radius_ > 0.f ? radius_ : 1.f;
  // Sum of weights x dphi = integral of luminance over the sphere.
  return float(kPiD * r * r * weight_sum_ * 2.0 * kPiD / width_);
}

namespace {

/// True when the linear part is a rotation, possibly mirrored and uniformly scaled.
bool is_similarity(const Transform& t) {
  const auto& m = t.matrix().m;
  double g[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      g[a][b] = 0;
      for (int k = 0; k < 3; ++k) g[a][b] += m[k][a] * m[k][b];
    }
  double s = (g[0][0] + g[1][1] + g[2][2]) / 3.0;
  if (!(s > 0)) return false;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (std::abs(g[a][b] - (a == b ? s : 0.0)) > 1e-4 * s) return false;
  return true;
}

}  // namespace

/// Mitsuba's `envmap`: `filename` (EXR, HDR, PFM or an LDR image, which is linearised),
/// `scale` (default 1), `to_world`.
std::unique_ptr<Light> make_envmap(const SceneNode& node, LoadContext& ctx) {
  const Property* file_prop = node.find("filename");
  FileLoc loc = file_prop ? file_prop->loc : node.loc;
  std::string filename = node.get_string("filename", "");
  if (filename.empty()) throw SceneError(node.loc, node.describe() + ": needs a 'filename'");
  std::string path = ctx.resolve_path(filename, loc);
  Image image;
  try {
    image = read_image(path);
  } catch (const SceneError& e) {
    throw SceneError(loc, node.describe() + ": " + e.what());
  }
  if (image.srgb_encoded()) image = image.linearized();
  if (image.width() < 2 || image.height() < 3)
    throw SceneError(loc, node.describe() + ": '" + filename + "' is " + std::to_string(image.width()) + "x" +
                              std::to_string(image.height()) + "; an environment map needs at least 2x3 texels");
  float scale = node.get_float("scale", 1.f);
  if (!std::isfinite(scale) || scale < 0.f)
    throw SceneError(node.loc, node.describe() + ": scale must be finite and non-negative");
  Transform to_world = node.get_transform("to_world", Transform());
  if (!is_similarity(to_world))
    ctx.warn(node.loc, node.describe() +
                           ": to_world is not a rotation; directions are re-normalised but importance "
                           "sampling ignores the distortion (MIS weights are approximate)");
  return std::make_unique<EnvmapLight>(image, scale, to_world);
}

}  // namespace tessera
