// Mitsuba's `null` BSDF: marks an index-matched medium boundary. Light crosses it unchanged, so it
// is a fully transparent surface (opacity 0) that the volume path tracer stops at only to switch
// media; sample() describes that crossing for callers that ask anyway.
#include "tessera/bsdf/null.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class NullBsdf final : public Bsdf {
 public:
  Rgb eval(const SurfaceInteraction&, Vec3, Vec3) const override { return {}; }
  float pdf(const SurfaceInteraction&, Vec3, Vec3) const override { return 0.f; }
  bool sample(const SurfaceInteraction&, Vec3 wo, float, Vec2, BsdfSample& out) const override {
    out.wi = -wo;
    out.pdf = 1.f;
    out.weight = Rgb(1.f);
    out.delta = true;
    out.eta = 1.f;
    return true;
  }
  bool is_delta() const override { return true; }
  bool has_opacity() const override { return true; }
  float opacity(const SurfaceInteraction&) const override { return 0.f; }
  bool is_null() const override { return true; }
};

}  // namespace

std::shared_ptr<Bsdf> make_null_bsdf() { return std::make_shared<NullBsdf>(); }

std::shared_ptr<Bsdf> make_null(const SceneNode&, LoadContext&) { return make_null_bsdf(); }

}  // namespace tessera
