#include "tessera/light/area.h"

#include "tessera/scene/load_context.h"

#include <cmath>

namespace tessera {
namespace {

class AreaLight final : public Light {
 public:
  AreaLight(const Shape& shape, Rgb radiance) : shape_(shape), radiance_(radiance) {}

  bool sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const override {
    Vec3 p, n;
    float pdf_area = 0.f;
    shape_.sample_area(u, p, n, pdf_area);
    Vec3 d = p - ref_p;
    float dist2 = length_squared(d);
    if (!(dist2 > 0.f) || !(pdf_area > 0.f)) return false;
    float dist = std::sqrt(dist2);
    Vec3 wi = d / dist;
    // Emission is one-sided: a point seen from behind contributes nothing.
    float cos_light = -dot(n, wi);
    if (!(cos_light > 0.f)) return false;
    out.wi = wi;
    out.li = radiance_;
    out.p_light = p;
    out.n_light = n;
    out.dist = dist;
    out.pdf = pdf_area * dist2 / cos_light;
    out.delta = false;
    return std::isfinite(out.pdf);
  }

  Rgb le(const SurfaceInteraction& si, Vec3 w) const override {
    return dot(si.ng, w) > 0.f ? radiance_ : Rgb();
  }

  float pdf_li(Vec3 ref_p, const SurfaceInteraction& si) const override {
    Vec3 d = si.p - ref_p;
    float dist2 = length_squared(d);
    if (!(dist2 > 0.f)) return 0.f;
    float cos_light = std::abs(dot(si.ng, d)) / std::sqrt(dist2);
    if (!(cos_light > 0.f)) return 0.f;
    // Shapes sample uniformly by area (see Shape::sample_area).
    float pdf = dist2 / (cos_light * shape_.area());
    return std::isfinite(pdf) ? pdf : 0.f;
  }

  float power() const override { return kPi * shape_.area() * radiance_.average(); }

 private:
  const Shape& shape_;
  Rgb radiance_;
};

}  // namespace

std::unique_ptr<Light> make_area_light(const Shape& shape, Rgb radiance) {
  return std::make_unique<AreaLight>(shape, radiance);
}

// Mitsuba's `area` emitter: `radiance` (0.6 default: white 1).
std::unique_ptr<Light> make_area_light(const SceneNode& emitter, LoadContext&, const Shape& shape) {
  return make_area_light(shape, emitter.get_color("radiance", Rgb(1.f)));
}

}  // namespace tessera
