// Reading the microfacet parameters the rough BSDFs share, so that every rough plugin spells,
// defaults and reports them the same way (Mitsuba 0.6 names, normalised to snake_case).
#pragma once

#include "tessera/bsdf/microfacet.h"
#include "tessera/render/texture.h"
#include "tessera/scene/load_context.h"

#include <memory>

namespace tessera {

/// `distribution`: beckmann (default), ggx, phong. Mitsuba's `as` (Ashikhmin-Shirley) is reported as
/// unsupported with Beckmann as the fallback; any other name is a SceneError at its line. Also reads
/// `sample_visible`, which changes only the variance.
MicrofacetType read_microfacet_type(const SceneNode& node, LoadContext& ctx);

struct MicrofacetAlpha {
  std::shared_ptr<Texture> u, v;
};
/// `alpha` sets both axes, `alpha_u`/`alpha_v` override each (default 0.1); each may be a texture.
MicrofacetAlpha read_microfacet_alpha(const SceneNode& node, LoadContext& ctx);

}  // namespace tessera
