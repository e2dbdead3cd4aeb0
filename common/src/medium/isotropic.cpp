// Mitsuba's `isotropic` phase function: every direction equally likely.
#include "tessera/core/sampling.h"
#include "tessera/render/medium.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class IsotropicPhase final : public PhaseFunction {
 public:
  float eval(Vec3, Vec3) const override { return kInv4Pi; }
  float sample(Vec3, Vec2 u, Vec3& wi, float& pdf) const override {
    wi = square_to_uniform_sphere(u);
    pdf = kInv4Pi;
    return 1.f;
  }
};

}  // namespace

std::unique_ptr<PhaseFunction> make_isotropic_phase() { return std::make_unique<IsotropicPhase>(); }

std::shared_ptr<PhaseFunction> make_isotropic(const SceneNode&, LoadContext&) { return make_isotropic_phase(); }

}  // namespace tessera
