// The portal distant lights emit through (emission_portal.h): its sampling, its density, and the
// pilot of camera paths that finds it.
#include "tessera/render/emission_portal.h"

#include "tessera/core/frame.h"
#include "tessera/core/hash.h"
#include "tessera/core/sampling.h"
#include "tessera/render/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace tessera {
namespace {

// The pilot: one camera path per cell of a kPilotSide^2 grid over the film, each followed by BSDF
// sampling for at most kMaxBounces surfaces. 4,096 paths cost a few tens of milliseconds and
// put hundreds of escapes on a window that lights a room.
constexpr uint32_t kPilotSide = 64;
static_assert(kPilotSide * kPilotSide == EmissionPortal::kPilotPaths);
constexpr int kMaxBounces = 24;
constexpr uint64_t kPilotSeed = 0x706f7274616cull;
// Fewer escapes than this say too little about where the light gets in: no portal.
constexpr size_t kMinEscapes = 32;
// Escapes are grouped by the cells of a kGrid^3 grid over the scene (kGrid^3 <= kMaxBoxes).
constexpr int kGrid = 4;
// Each group's box grows by this fraction of the scene's diagonal on every side, so that the
// parts of an opening between the pilot's escapes are covered too.
constexpr float kPad = 0.01f;

// The area of face k of `b` (perpendicular to axis k) projected along `dir`.
float face_area(const Bounds3& b, int k, Vec3 dir) {
  const Vec3 e = b.diagonal();
  return std::abs(dir[k]) * e[(k + 1) % 3] * e[(k + 2) % 3];
}

// Whether the infinite line through p along dir meets `b` (faces included).
bool crosses(const Bounds3& b, Vec3 p, Vec3 dir) {
  float t0 = -std::numeric_limits<float>::infinity(), t1 = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.f) {
      if (p[k] < b.lo[k] || p[k] > b.hi[k]) return false;
      continue;
    }
    float a = (b.lo[k] - p[k]) / dir[k], c = (b.hi[k] - p[k]) / dir[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
  }
  return t0 <= t1;
}

float pilot_u(uint32_t path, uint32_t dim) {
  return bits_to_unit_float(uint32_t(hash_values(kPilotSeed, path, dim) >> 32));
}

// Where the pilot's camera paths leave the scene: the origin of each escaping ray after at least
// one surface (a camera ray that sees the sky directly needs no light subpath).
std::vector<Vec3> pilot_escapes(const Scene& scene) {
  std::vector<Vec3> escapes;
  const float w = float(scene.film.width), h = float(scene.film.height);
  for (uint32_t i = 0; i < kPilotSide * kPilotSide; ++i) {
    const Vec2 raster((float(i % kPilotSide) + pilot_u(i, 0)) / float(kPilotSide) * w,
                      (float(i / kPilotSide) + pilot_u(i, 1)) / float(kPilotSide) * h);
    Ray ray = scene.camera->generate_ray_at(raster, Vec2(pilot_u(i, 2), pilot_u(i, 3)), scene.shutter_open);
    for (int bounce = 0; bounce < kMaxBounces; ++bounce) {
      SurfaceInteraction si;
      if (!scene.intersect(ray, si)) {
        if (bounce > 0) escapes.push_back(ray.o);
        break;
      }
      const Bsdf* bsdf = si.bsdf();
      const Vec3 wo = normalize(-ray.d);
      if (!bsdf || !reconcile_shading_frame(si, wo, false)) break;
      const uint32_t dim = 4 + 3 * uint32_t(bounce);
      BsdfSample bs;
      if (!bsdf->sample(si, si.to_local(wo), pilot_u(i, dim), Vec2(pilot_u(i, dim + 1), pilot_u(i, dim + 2)), bs))
        break;
      const Vec3 wi = si.to_world(bs.wi);
      if (!consistent_side(si, wi, bs.wi)) break;
      ray = spawn_ray(si, wi);
      ray.time = scene.shutter_open;
    }
  }
  return escapes;
}

int grid_cell(const Bounds3& bounds, Vec3 p) {
  int cell = 0;
  for (int k = 2; k >= 0; --k) {
    const float extent = bounds.hi[k] - bounds.lo[k];
    const float f = extent > 0.f ? (p[k] - bounds.lo[k]) / extent : 0.f;
    cell = cell * kGrid + std::clamp(int(f * float(kGrid)), 0, kGrid - 1);
  }
  return cell;
}

}  // namespace

void EmissionPortal::add_box(const Bounds3& b) {
  if (count_ >= kMaxBoxes || b.empty()) return;
  boxes_[size_t(count_++)] = b;
  const Vec3 e = b.diagonal();
  for (int k = 0; k < 3; ++k) face_area_sum_[size_t(k)] += e[(k + 1) % 3] * e[(k + 2) % 3];
}

float EmissionPortal::projected_area(Vec3 dir) const {
  return std::abs(dir.x) * face_area_sum_[0] + std::abs(dir.y) * face_area_sum_[1] + std::abs(dir.z) * face_area_sum_[2];
}

Vec3 EmissionPortal::box_point(Vec3 dir, Vec2 u) const {
  // A (box, front face) in proportion to its projected area; what is left of u.x, rescaled,
  // places the point along one edge of that face.
  float target = u.x * projected_area(dir), area = 0.f;
  int box = 0, axis = 0;
  for (int i = 0; i < count_ * 3; ++i) {
    const float a = face_area(boxes_[size_t(i / 3)], i % 3, dir);
    if (!(a > 0.f)) continue;
    box = i / 3, axis = i % 3, area = a;
    if (target < a) break;
    target -= a;
  }
  const float v = area > 0.f ? std::clamp(target / area, 0.f, 0x1.fffffep-1f) : 0.f;
  const Bounds3& b = boxes_[size_t(box)];
  const int j = (axis + 1) % 3, l = (axis + 2) % 3;
  Vec3 q;
  q[axis] = dir[axis] > 0.f ? b.lo[axis] : b.hi[axis];
  q[j] = b.lo[j] + v * (b.hi[j] - b.lo[j]);
  q[l] = b.lo[l] + u.y * (b.hi[l] - b.lo[l]);
  return q;
}

bool EmissionPortal::sample(Vec3 dir, Vec2 u, Vec3& p, float& pdf) const {
  if (!active()) return false;
  const float disk_share = count_ > 0 && projected_area(dir) > 0.f ? kDiskShare : 1.f;
  Vec3 q;
  if (u.x < disk_share) {
    const Frame frame(dir);
    const Vec2 d = square_to_uniform_disk_concentric(Vec2(u.x / disk_share, u.y));
    q = center_ + (frame.s * d.x + frame.t * d.y) * radius_;
  } else {
    q = box_point(dir, Vec2(std::min((u.x - disk_share) / (1.f - disk_share), 0x1.fffffep-1f), u.y));
  }
  // The density of q's line (a box point's line crosses its box exactly: every slab's interval
  // holds q itself), then the start moved upstream along it, out of the scene's bounding sphere.
  pdf = this->pdf(q, dir);
  p = q - dir * (length(q - center_) + radius_);
  return pdf > 0.f && std::isfinite(pdf);
}

float EmissionPortal::pdf(Vec3 p, Vec3 dir) const {
  if (!active()) return 0.f;
  const Vec3 off = p - center_;
  const bool in_disk = length_squared(off - dir * dot(off, dir)) <= radius_ * radius_;
  const float total = count_ > 0 ? projected_area(dir) : 0.f;
  const float disk_share = total > 0.f ? kDiskShare : 1.f;
  float pdf = in_disk ? disk_share / (kPi * radius_ * radius_) : 0.f;
  if (total > 0.f) {
    int crossed = 0;
    for (int i = 0; i < count_; ++i) crossed += crosses(boxes_[size_t(i)], p, dir) ? 1 : 0;
    pdf += (1.f - disk_share) * float(crossed) / total;
  }
  return std::isfinite(pdf) ? pdf : 0.f;
}

EmissionPortal find_emission_portal(const Scene& scene) {
  EmissionPortal portal;
  const Bounds3 bounds = scene.bounds();
  const float radius = 0.5f * length(bounds.diagonal());
  if (bounds.empty() || !(radius > 0.f) || !std::isfinite(radius)) return portal;
  portal.set_scene_sphere(bounds.center(), radius);
  if (!scene.camera || scene.film.width <= 0 || scene.film.height <= 0) return portal;
  const std::vector<Vec3> escapes = pilot_escapes(scene);
  if (escapes.size() < kMinEscapes) return portal;
  std::array<Bounds3, kGrid * kGrid * kGrid> cells{};
  for (const Vec3& p : escapes) cells[size_t(grid_cell(bounds, p))].extend(p);
  const float pad = kPad * length(bounds.diagonal());
  for (Bounds3 b : cells) {
    if (b.empty()) continue;
    b.lo = vmax(b.lo - Vec3(pad), bounds.lo);
    b.hi = vmin(b.hi + Vec3(pad), bounds.hi);
    portal.add_box(b);
  }
  portal.set_escapes(uint32_t(escapes.size()));
  return portal;
}

}  // namespace tessera
