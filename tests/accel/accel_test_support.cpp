#include "accel_test_support.h"

#include <map>
#include <utility>

namespace tessera::test {

std::vector<Triangle> icosphere(Vec3 center, float radius, int levels) {
  const float g = (1.f + std::sqrt(5.f)) * 0.5f;
  std::vector<Vec3> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& p : v) p = normalize(p);
  std::vector<std::array<uint32_t, 3>> f = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(normalize((v[a] + v[b]) * 0.5f));
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (auto [a, b, c] : f) {
      uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  for (auto& p : v) p = center + p * radius;
  std::vector<Triangle> tris;
  for (auto [a, b, c] : f) tris.push_back({v[a], v[b], v[c]});
  return tris;
}

std::vector<Triangle> grid_box(Vec3 lo, Vec3 hi, int n) {
  // Lattice point (i, j, k) in [0, n]^3; every face computes a shared point the same way.
  auto lattice = [&](int i, int j, int k) {
    const int idx[3] = {i, j, k};
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = lo[a] + (hi[a] - lo[a]) * (float(idx[a]) / float(n));
    return p;
  };
  std::vector<Triangle> tris;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int side = 0; side <= n; side += n) {
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          auto at = [&](int da, int db) {
            int idx[3];
            idx[axis] = side;
            idx[u] = a + da;
            idx[w] = b + db;
            return lattice(idx[0], idx[1], idx[2]);
          };
          tris.push_back({at(0, 0), at(1, 0), at(1, 1)});
          tris.push_back({at(0, 0), at(1, 1), at(0, 1)});
        }
    }
  }
  return tris;
}

}  // namespace tessera::test
