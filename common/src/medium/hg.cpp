// Mitsuba's `hg` phase function (Henyey and Greenstein 1941):
//   p(cos) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^{3/2}),  cos = dot(-wo, wi),
// sampled exactly by inverting its CDF in cos, so eval == pdf and the sample weight is 1.
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/render/medium.h"
#include "tessera/scene/error.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

// Below this |g| the inverse CDF divides by ~0; the distribution is then uniform to float precision.
constexpr float kIsotropicG = 1e-3f;

class HgPhase final : public PhaseFunction {
 public:
  explicit HgPhase(float g) : g_(g) { TESSERA_CHECK(g > -1.f && g < 1.f); }

  float eval(Vec3 wo, Vec3 wi) const override { return density(-dot(wo, wi)); }

  float sample(Vec3 wo, Vec2 u, Vec3& wi, float& pdf) const override {
    float cos_theta;
    if (std::abs(g_) < kIsotropicG) {
      cos_theta = 1.f - 2.f * u.x;
    } else {
      float s = (1.f - g_ * g_) / (1.f - g_ + 2.f * g_ * u.x);
      cos_theta = (1.f + g_ * g_ - s * s) / (2.f * g_);
    }
    cos_theta = std::clamp(cos_theta, -1.f, 1.f);
    float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    float phi = 2.f * kPi * u.y;
    Frame forward(-wo);
    wi = forward.to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
    pdf = density(cos_theta);
    return 1.f;
  }

 private:
  float density(float cos_theta) const {
    float denom = 1.f + g_ * g_ - 2.f * g_ * cos_theta;
    return kInv4Pi * (1.f - g_ * g_) / (denom * std::sqrt(std::max(denom, 1e-12f)));
  }

  float g_;
};

}  // namespace

std::unique_ptr<PhaseFunction> make_hg_phase(float g) { return std::make_unique<HgPhase>(g); }

std::shared_ptr<PhaseFunction> make_hg(const SceneNode& node, LoadContext&) {
  float g = node.get_float("g", 0.8f);
  if (!(g > -1.f && g < 1.f)) throw SceneError(node.loc_of("g"), "the hg phase function's g must lie in (-1, 1)");
  return make_hg_phase(g);
}

}  // namespace tessera
