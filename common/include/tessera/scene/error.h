// Errors in user input (scene files, meshes, images). They carry the file and line, are thrown only
// while parsing and loading (never on the hot path) and are caught once at the command/job boundary.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace tessera {

struct FileLoc {
  std::string file;  // as the user named it (relative paths kept relative)
  int line = 0;      // 1-based; 0 when unknown
  std::string str() const { return line > 0 ? file + ":" + std::to_string(line) : file; }
};

class SceneError : public std::runtime_error {
 public:
  SceneError(const FileLoc& loc, const std::string& msg)
      : std::runtime_error(loc.str() + ": " + msg), loc_(loc) {}
  explicit SceneError(const std::string& msg) : std::runtime_error(msg) {}
  const FileLoc& loc() const { return loc_; }

 private:
  FileLoc loc_;
};

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
