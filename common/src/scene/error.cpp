#include "tessera/scene/error.h"

#include <utility>

namespace tessera {

namespace {

std::string list_items(const std::vector<UnsupportedItem>& items) {
  std::string msg = "the scene uses " + std::to_string(items.size()) +
                    " unsupported feature(s); --allow-unsupported renders with the fallbacks:";
  for (const auto& it : items) {
    msg += '\n';
    msg += it.loc.str();
    msg += ": ";
    msg += it.what;
    msg += " (fallback: ";
    msg += it.fallback;
    msg += ')';
  }
  return msg;
}

}  // namespace

UnsupportedError::UnsupportedError(std::vector<UnsupportedItem> items)
    : SceneError(list_items(items)), items_(std::move(items)) {}

}  // namespace tessera
