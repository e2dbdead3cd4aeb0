// Points (photons, light vertices) in a hash grid for fixed-radius queries: a photon mapper's and
// vertex merging's search structure (sppm.h, vcm.h).
//
// Cells are cubes of side twice the largest query radius, so a query visits at most 2 cells per
// axis (8 in all). Buckets are Teschner et al. 2003's spatial hash of the cell; records are sorted
// into them by a stable counting sort, so the order within a bucket is the order given (a function
// of the pass alone) and a query's sum is the same bits on any machine. Immutable once built;
// queries are thread-safe.
#pragma once

#include "tessera/core/check.h"
#include "tessera/core/vec.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

namespace tessera {

/// R has `float p[3]`, its position.
template <typename R>
class PointGrid {
 public:
  PointGrid() = default;
  /// Records in the order given, for queries of radius at most `max_radius` > 0.
  PointGrid(std::vector<R> records, float max_radius);

  /// Calls f(record) for every record within distance `r` (<= max_radius()) of `p`, in a fixed
  /// order.
  template <typename F>
  void for_each_near(Vec3 p, float r, F&& f) const;

  size_t size() const { return records_.size(); }
  float max_radius() const { return 0.5f * cell_; }
  const std::vector<R>& records() const { return records_; }
  size_t memory_bytes() const { return records_.size() * sizeof(R) + starts_.size() * sizeof(uint32_t); }

 private:
  uint32_t bucket(int x, int y, int z) const {
    return ((uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ (uint32_t(z) * 83492791u)) & mask_;
  }
  // (Clamped: a radius far below the coordinates' scale must not overflow the cell index.)
  int cell_of(float v) const { return int(std::clamp(std::floor(v / cell_), -1073741824.f, 1073741824.f)); }
  std::vector<R> records_;        // sorted by bucket, stable
  std::vector<uint32_t> starts_;  // per bucket: its first record; one more at the end
  float cell_ = 1.f;
  uint32_t mask_ = 0;
};

template <typename R>
PointGrid<R>::PointGrid(std::vector<R> records, float max_radius) : cell_(2.f * max_radius) {
  TESSERA_CHECK(max_radius > 0.f && std::isfinite(max_radius));
  TESSERA_CHECK(records.size() < (uint64_t(1) << 32));
  const uint32_t buckets = std::bit_ceil(uint32_t(std::max<size_t>(records.size(), 1)));
  mask_ = buckets - 1;
  std::vector<uint32_t> key(records.size());
  starts_.assign(size_t(buckets) + 1, 0);
  for (size_t i = 0; i < records.size(); ++i) {
    key[i] = bucket(cell_of(records[i].p[0]), cell_of(records[i].p[1]), cell_of(records[i].p[2]));
    ++starts_[key[i] + 1];
  }
  for (size_t b = 0; b < buckets; ++b) starts_[b + 1] += starts_[b];
  records_.resize(records.size());
  std::vector<uint32_t> next(starts_.begin(), starts_.end() - 1);
  for (size_t i = 0; i < records.size(); ++i) records_[next[key[i]]++] = records[i];
}

template <typename R>
template <typename F>
void PointGrid<R>::for_each_near(Vec3 p, float r, F&& f) const {
  if (records_.empty()) return;
  const int x0 = cell_of(p.x - r), y0 = cell_of(p.y - r), z0 = cell_of(p.z - r);
  const int x1 = cell_of(p.x + r), y1 = cell_of(p.y + r), z1 = cell_of(p.z + r);
  uint32_t seen[8];
  int n_seen = 0;
  const float r2 = r * r;
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const uint32_t b = bucket(x, y, z);
        bool dup = false;  // (two cells may share a bucket: visit it once)
        for (int k = 0; k < n_seen; ++k) dup = dup || seen[k] == b;
        if (dup || n_seen == 8) continue;
        seen[n_seen++] = b;
        for (uint32_t i = starts_[b]; i < starts_[b + 1]; ++i) {
          const R& rec = records_[i];
          const float dx = rec.p[0] - p.x, dy = rec.p[1] - p.y, dz = rec.p[2] - p.z;
          if (dx * dx + dy * dy + dz * dz <= r2) f(rec);
        }
      }
}

}  // namespace tessera
