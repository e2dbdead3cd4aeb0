// Scene bundles: a scene folder packed as .tar.gz or .zip, the unit a job's scene travels in.
//
// Unpacking is the security boundary of the farm (bundles come from the network): every entry
// must be a regular file or directory with a relative path that stays inside the destination, no
// `..`, no absolute path, no symlink, hard link or device; entry count and unpacked bytes are
// bounded (decompression bombs). A bad bundle is refused as a whole with a message naming the
// entry; nothing is left behind in the destination.
//
// Real scenes compress less than 10:1 (meshes, textures, XML); a bundle that inflates far beyond
// that is a bomb whatever its absolute size, so the unpacked size is also bounded in proportion to
// the bundle's own size (past a floor that keeps tiny scenes free of the rule).
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace tessera {

struct SceneDesc;
struct LoadResult;

struct BundleLimits {
  uint64_t max_files = 100000;
  uint64_t max_unpacked_bytes = uint64_t(16) << 30;  // 16 GiB
  // A bundle may unpack to at most ratio_floor_bytes + max_ratio x its own size; 0: no such limit.
  double max_ratio = 200;
  uint64_t ratio_floor_bytes = uint64_t(8) << 20;  // 8 MiB

  /// The unpacked bytes a bundle of `bundle_bytes` may hold: the smaller of both limits.
  uint64_t unpacked_limit(uint64_t bundle_bytes) const;
};

struct BundleEntry {
  std::string path;   // relative, '/'-separated, normalised (no "./")
  uint64_t size = 0;
};

/// Result of inspecting or unpacking: `error` empty on success.
struct BundleResult {
  std::string error;               // what is wrong, naming the entry
  std::vector<BundleEntry> files;  // regular files (listed or written), in archive order
  bool ok() const { return error.empty(); }
};

/// Lists and validates a bundle's bytes (in memory, or a mapped file: mapped_file.h; format detected
/// from content: gzip'd tar, plain tar or zip). Reads every entry, so truncated or corrupt archives
/// are caught.
[[nodiscard]] BundleResult inspect_bundle(std::string_view bytes, const BundleLimits& limits = {});

/// Validates, then writes the bundle's files under `dest_dir` (created if needed). With `only`,
/// writes only those relative paths (the files a scene references) and fails if one is missing.
/// Writes into a temporary sibling directory and renames it into place, so a failure leaves no
/// partial tree; if `dest_dir` already exists it is replaced.
[[nodiscard]] BundleResult unpack_bundle(std::string_view bytes, const std::string& dest_dir,
                                         const BundleLimits& limits = {},
                                         const std::optional<std::set<std::string>>& only = std::nullopt);

/// The scene XML of a bundle: `requested` if given (must be an entry ending in .xml), else the
/// single *.xml at the bundle's root. Empty result + `error` set when ambiguous or missing.
[[nodiscard]] std::string find_scene_xml(const std::vector<BundleEntry>& files, const std::string& requested,
                                         std::string& error);

/// Packs `files` (paths relative to `root_dir`, '/'-separated) as a gzip'd tar in memory.
/// Throws std::runtime_error naming the file if one cannot be read.
std::string pack_bundle(const std::string& root_dir, const std::vector<std::string>& files);

/// The files a scene needs, as given by the scene's loader: absolute or relative paths, in any
/// form. Returns (common root directory, paths relative to it with the scene XML first). The root
/// is the deepest directory containing every file, so `../textures/x.png` references survive.
struct BundlePlan {
  std::string root_dir;
  std::vector<std::string> files;  // relative to root_dir; files[0] is the scene XML
};
BundlePlan plan_bundle(const std::string& scene_xml, const std::vector<std::string>& referenced);

/// Every file loading `desc` read, for plan_bundle: the scene XML, its <include>d files and
/// <spectrum filename=..> files (parser), then each file the loader resolved (meshes, images),
/// without repeats, in first-use order. Only what the loaded plugins used: a file named by an
/// unsupported plugin (allow_unsupported) is not listed.
std::vector<std::string> scene_files(const SceneDesc& desc, const LoadResult& loaded);

}  // namespace tessera
