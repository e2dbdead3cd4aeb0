// Keeping a scene's files inside one directory (a farm bundle unpacked on the coordinator or a
// worker): a scene from the network must not read `../../etc/passwd` or `/abs/path.obj`, nor follow
// a symlink out of its folder. An empty root confines nothing (local `tessera render`).
#pragma once

#include "tessera/scene/error.h"

#include <filesystem>
#include <string>

namespace tessera::detail {

/// `p` lies under `root` once both are made absolute and lexically normal. Decided without touching
/// the disk, so it can screen a name before anything is looked up. True when `root` is empty.
bool lexically_inside(const std::string& root, const std::filesystem::path& p);

/// `p` lies under `root` after both have their symlinks resolved (weakly_canonical). True when
/// `root` is empty.
bool canonically_inside(const std::string& root, const std::filesystem::path& p);

/// Both of the above: what a file must pass before it is opened.
inline bool inside_root(const std::string& root, const std::filesystem::path& p) {
  return lexically_inside(root, p) && canonically_inside(root, p);
}

/// SceneError(loc, "file 'name' is outside the scene bundle"); `name` as the scene wrote it.
[[noreturn]] void throw_outside_root(const FileLoc& loc, const std::string& name);

}  // namespace tessera::detail
