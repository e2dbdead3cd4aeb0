// The look-ahead pass of scene loading that decodes every bitmap file at once, in parallel,
// instead of one by one as the build meets the textures.
#pragma once

#include "tessera/scene/load_context.h"

namespace tessera {

/// Decodes, concurrently, every bitmap texture file the scene description names (each distinct
/// file and decoding once) into `ctx`'s resource cache, where the bitmap factory then finds them.
/// Reads parameters without marking them used or logging them. A bitmap whose parameters or file
/// are wrong is skipped: the factory meets it again and reports it with its location. What ends
/// up in the cache does not depend on the number of threads.
void prefetch_bitmaps(LoadContext& ctx);

}  // namespace tessera
