// Helpers shared by the image readers and writers (private to src/image).
#pragma once

#include "tessera/core/error.h"

#include <string>

namespace tessera::image_detail {

[[noreturn]] inline void fail(const std::string& path, const std::string& msg) {
  throw SceneError(FileLoc{path, 0}, msg);
}

/// Throws unless `path` names an existing regular file.
void require_readable_file(const std::string& path);

/// Lower-case extension with the dot (".exr"), empty when there is none.
std::string lower_extension(const std::string& path);

}  // namespace tessera::image_detail
