// The scene loader's report of plugins and parameters it does not model. The error type itself
// (SceneError, with file and line) is in core/error.h.
#pragma once

#include "tessera/core/error.h"

#include <string>
#include <vector>

namespace tessera {

/// One plugin or parameter that would change the image but is not modeled.
struct UnsupportedItem {
  FileLoc loc;
  std::string what;      // e.g. "bsdf 'roughplastic'" or "parameter 'alpha' of bsdf 'diffuse'"
  std::string fallback;  // what --allow-unsupported substitutes
};

/// Thrown once, after the whole scene was read, listing every unsupported item.
class UnsupportedError : public SceneError {
 public:
  explicit UnsupportedError(std::vector<UnsupportedItem> items);
  const std::vector<UnsupportedItem>& items() const { return items_; }

 private:
  std::vector<UnsupportedItem> items_;
};

}  // namespace tessera
