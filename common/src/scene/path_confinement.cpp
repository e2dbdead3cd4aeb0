// Containment is decided component by component, never by string prefix: "/b/bundle2" is not
// inside "/b/bundle".
#include "scene/path_confinement.h"

#include <algorithm>

namespace tessera::detail {

namespace fs = std::filesystem;

namespace {

// "/a/b/" and "/a/b" name the same directory; the trailing empty component would break the match.
fs::path without_trailing_separator(fs::path p) {
  if (!p.has_filename() && p.has_relative_path()) p = p.parent_path();
  return p;
}

bool is_under(const fs::path& root, const fs::path& p) {
  const fs::path r = without_trailing_separator(root);
  auto [ri, pi] = std::mismatch(r.begin(), r.end(), p.begin(), p.end());
  return ri == r.end();
}

}  // namespace

bool lexically_inside(const std::string& root, const fs::path& p) {
  if (root.empty()) return true;
  std::error_code ec_root, ec_path;
  const fs::path r = fs::absolute(root, ec_root);
  const fs::path a = fs::absolute(p, ec_path);
  // When the file system cannot answer (no working directory), the file is not known to be inside.
  if (ec_root || ec_path) return false;
  // Normal absolute paths hold no ".." after their root, so a component match is containment.
  return is_under(r.lexically_normal(), a.lexically_normal());
}

bool canonically_inside(const std::string& root, const fs::path& p) {
  if (root.empty()) return true;
  // Absolute first: for a relative name of which no part exists yet, weakly_canonical would stay
  // relative and never match.
  std::error_code ec[4];
  const fs::path r = fs::weakly_canonical(fs::absolute(root, ec[0]), ec[1]);
  const fs::path c = fs::weakly_canonical(fs::absolute(p, ec[2]), ec[3]);
  for (const std::error_code& e : ec)
    if (e) return false;
  return is_under(r, c);
}

void throw_outside_root(const FileLoc& loc, const std::string& name) {
  throw SceneError(loc, "file '" + name + "' is outside the scene bundle");
}

}  // namespace tessera::detail
