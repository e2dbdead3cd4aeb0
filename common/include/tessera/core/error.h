// Errors in user input (scene files, meshes, images). They carry the file and line, are thrown only
// while parsing and loading (never on the hot path) and are caught once at the command/job boundary.
// Every layer that reads a user's file (image decoders, mesh readers, the scene loader) throws these,
// so they live at the bottom; the loader's report of unsupported features is in scene/error.h.
#pragma once

#include <stdexcept>
#include <string>

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

}  // namespace tessera
