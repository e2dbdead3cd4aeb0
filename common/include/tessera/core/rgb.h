// Linear RGB radiometric quantity (Rec. 709 primaries, as Mitsuba's rgb variants). Spectra in scene
// files are reduced to RGB at load time.
#pragma once

#include <algorithm>
#include <cmath>

namespace tessera {

struct Rgb {
  float r = 0, g = 0, b = 0;
  constexpr Rgb() = default;
  constexpr Rgb(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
  constexpr explicit Rgb(float s) : r(s), g(s), b(s) {}
  constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr Rgb& operator+=(Rgb o) { r += o.r; g += o.g; b += o.b; return *this; }
  constexpr Rgb& operator*=(Rgb o) { r *= o.r; g *= o.g; b *= o.b; return *this; }
  constexpr Rgb& operator*=(float s) { r *= s; g *= s; b *= s; return *this; }
  constexpr bool operator==(const Rgb&) const = default;
  constexpr bool is_black() const { return r == 0.f && g == 0.f && b == 0.f; }
  constexpr float max_value() const { return std::max(r, std::max(g, b)); }
  constexpr float average() const { return (r + g + b) / 3.f; }
  /// Rec. 709 luminance; used for light power and Russian roulette.
  constexpr float luminance() const { return 0.212671f * r + 0.715160f * g + 0.072169f * b; }
  bool is_finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
};

constexpr Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
constexpr Rgb operator-(Rgb a, Rgb b) { return {a.r - b.r, a.g - b.g, a.b - b.b}; }
constexpr Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
constexpr Rgb operator/(Rgb a, Rgb b) { return {a.r / b.r, a.g / b.g, a.b / b.b}; }
constexpr Rgb operator*(Rgb a, float s) { return {a.r * s, a.g * s, a.b * s}; }
constexpr Rgb operator*(float s, Rgb a) { return {a.r * s, a.g * s, a.b * s}; }
constexpr Rgb operator/(Rgb a, float s) { return {a.r / s, a.g / s, a.b / s}; }

/// sRGB transfer function (IEC 61966-2-1), per channel.
inline float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
inline float linear_to_srgb(float v) {
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

}  // namespace tessera
