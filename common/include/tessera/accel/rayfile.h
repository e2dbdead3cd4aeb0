// Ray files (RBRAYS01) and hit files (RBHITS01): fixed ray workloads and their answers, as specified
// in ../shared/docs/rayfile.md. Little-endian on disk whatever the host.
#pragma once

#include "tessera/core/ray.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace tessera {

/// Malformed or unreadable ray/hit file. The message names the file and what is wrong.
class RayFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class RayQuery : uint32_t { Closest = 0, Occlusion = 1 };

struct RaySet {
  std::string name;  // at most 16 bytes on disk
  RayQuery query = RayQuery::Closest;
  std::vector<Ray> rays;  // tmin/tmax are the file's tnear/tfar
};

struct RayFile {
  std::string info;  // provenance text
  std::vector<RaySet> sets;
};

/// One answer: closest hit (t, prim) or miss (+inf, kNoHit); occlusion: (0, 0) when occluded,
/// (+inf, kNoHit) when free.
struct HitRecord {
  float t = kInfinity;
  uint32_t prim = 0xFFFFFFFFu;
  static constexpr uint32_t kNoHit = 0xFFFFFFFFu;
  bool is_hit() const { return prim != kNoHit; }
};

struct HitSet {
  std::string name;
  RayQuery query = RayQuery::Closest;
  std::vector<HitRecord> hits;
};

struct HitFile {
  std::string info;
  std::vector<HitSet> sets;
};

/// Throw RayFileError on a missing file, bad magic or version, unknown query, wrong record size,
/// a truncated set, or trailing bytes.
RayFile read_ray_file(const std::string& path);
HitFile read_hit_file(const std::string& path);
/// Throw RayFileError when the file cannot be written or a set name exceeds 16 bytes.
void write_ray_file(const std::string& path, const RayFile& file);
void write_hit_file(const std::string& path, const HitFile& file);

/// The agreement rule of rayfile.md: both hit or both miss, and hits within 1e-4 relative in t.
bool hits_agree(const HitRecord& a, const HitRecord& b);

struct SetAgreement {
  std::string name;
  uint64_t count = 0;
  uint64_t disagree = 0;
  double fraction() const { return count ? double(disagree) / double(count) : 0.0; }
};

/// Compares two hit files set by set. Throws RayFileError when they do not answer the same sets
/// (set count, names, queries or record counts differ).
std::vector<SetAgreement> compare_hit_files(const HitFile& a, const HitFile& b);

/// Throws RayFileError unless `hits` answers `rays` (same set count, names, queries, counts).
void check_hits_match_rays(const RayFile& rays, const HitFile& hits, const std::string& what);

}  // namespace tessera
