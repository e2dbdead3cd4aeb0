#pragma once

#include "tessera/core/vec.h"

#include <limits>

namespace tessera {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;
inline constexpr float kInv2Pi = 0.15915494309189533577f;
inline constexpr float kInv4Pi = 0.07957747154594766788f;

/// A ray segment o + t d for t in [tmin, tmax]. `d` need not be normalised unless a caller says so.
struct Ray {
  Vec3 o;
  Vec3 d;
  float tmin = 0.f;
  float tmax = kInfinity;
  float time = 0.f;  // scene time of the ray, within the camera's shutter (motion blur)
  Vec3 at(float t) const { return o + d * t; }
};

}  // namespace tessera
