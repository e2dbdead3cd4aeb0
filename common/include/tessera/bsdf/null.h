// Mitsuba's `null` BSDF (an index-matched medium boundary), constructible without a scene file.
#pragma once

#include "tessera/render/bsdf.h"

#include <memory>

namespace tessera {

std::shared_ptr<Bsdf> make_null_bsdf();

}  // namespace tessera
