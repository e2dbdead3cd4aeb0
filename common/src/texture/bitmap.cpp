// Mitsuba's `bitmap` texture: an image file looked up at the surface's uv, decoded once per scene
// (texture/bitmap_prefetch.h, LoadContext::cached_resource) and filtered bilinearly (or nearest)
// as Mitsuba 0.6's MIPMap does at its finest level.
#include "tessera/texture/bitmap.h"

#include "tessera/scene/load_context.h"
#include "tessera/texture/bitmap_prefetch.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

namespace tessera {

std::optional<WrapMode> parse_wrap_mode(const std::string& name) {
  if (name == "repeat") return WrapMode::Repeat;
  if (name == "mirror") return WrapMode::Mirror;
  if (name == "clamp") return WrapMode::Clamp;
  if (name == "zero" || name == "black") return WrapMode::Zero;
  if (name == "one" || name == "white") return WrapMode::One;
  return std::nullopt;
}

UvMapping::UvMapping(const Transform& to_uv) {
  // uv lives in the xy plane of Mitsuba's 4x4 <transform>; z is ignored.
  const auto& m = to_uv.matrix().m;
  m_[0] = float(m[0][0]), m_[1] = float(m[0][1]), m_[2] = float(m[0][3]);
  m_[3] = float(m[1][0]), m_[4] = float(m[1][1]), m_[5] = float(m[1][3]);
}

BitmapTexture::BitmapTexture(std::shared_ptr<const TexelStorage> texels, WrapMode wrap_u, WrapMode wrap_v,
                             TextureFilter filter, UvMapping to_uv)
    : texels_(std::move(texels)), wrap_u_(wrap_u), wrap_v_(wrap_v), filter_(filter), to_uv_(to_uv) {
  TESSERA_CHECK(texels_ && !texels_->empty());
}

BitmapTexture::BitmapTexture(const std::shared_ptr<const Image>& image, WrapMode wrap_u, WrapMode wrap_v,
                             TextureFilter filter, UvMapping to_uv)
    : BitmapTexture(std::make_shared<const TexelStorage>(*image), wrap_u, wrap_v, filter, to_uv) {}

int BitmapTexture::wrap(int i, int n, WrapMode mode) {
  switch (mode) {
    case WrapMode::Repeat: {
      int r = i % n;
      return r < 0 ? r + n : r;
    }
    case WrapMode::Mirror: {
      int r = i % (2 * n);
      if (r < 0) r += 2 * n;
      return r >= n ? 2 * n - r - 1 : r;
    }
    case WrapMode::Clamp: return std::clamp(i, 0, n - 1);
    case WrapMode::Zero: return i >= 0 && i < n ? i : -1;
    case WrapMode::One: return i >= 0 && i < n ? i : -2;
  }
  return -1;
}

template <typename T, typename Fetch>
T BitmapTexture::texel(int x, int y, Fetch fetch) const {
  // u decided first, as Mitsuba does.
  int xi = wrap(x, texels_->width(), wrap_u_);
  if (xi < 0) return T(xi == -1 ? 0.f : 1.f);
  int yi = wrap(y, texels_->height(), wrap_v_);
  if (yi < 0) return T(yi == -1 ? 0.f : 1.f);
  return fetch(xi, yi);
}

template <typename Fetch>
auto BitmapTexture::filtered(Vec2 uv, Fetch fetch) const {
  using T = decltype(fetch(0, 0));
  auto texel = [&](int x, int y) -> T { return this->texel<T>(x, y, fetch); };
  float u = uv.x * float(texels_->width()), v = uv.y * float(texels_->height());
  // NaN/huge coordinates would overflow the integer conversion; Mitsuba returns 0 for NaN.
  if (!(std::abs(u) < 1e9f) || !(std::abs(v) < 1e9f)) return T(0.f);
  if (filter_ == TextureFilter::Nearest) return texel(int(std::floor(u)), int(std::floor(v)));
  u -= 0.5f;
  v -= 0.5f;
  float fx = std::floor(u), fy = std::floor(v);
  int x = int(fx), y = int(fy);
  float dx = u - fx, dy = v - fy;
  return texel(x, y) * ((1.f - dx) * (1.f - dy)) + texel(x, y + 1) * ((1.f - dx) * dy) +
         texel(x + 1, y) * (dx * (1.f - dy)) + texel(x + 1, y + 1) * (dx * dy);
}

Rgb BitmapTexture::lookup(Vec2 uv) const {
  const TexelStorage& t = *texels_;
  return t.visit([&](auto format) {
    return filtered(uv, [&t](int x, int y) { return t.rgb_as<decltype(format)::value>(x, y); });
  });
}

float BitmapTexture::lookup_channel(Vec2 uv, int channel) const {
  TESSERA_DCHECK(channel >= 0 && channel < 4);
  const TexelStorage& t = *texels_;
  if (channel == 3 && !t.has_alpha()) return 1.f;
  int c = t.channels() == 1 && channel < 3 ? 0 : channel;
  return t.visit([&](auto format) {
    return filtered(uv, [&t, c](int x, int y) { return t.at_as<decltype(format)::value>(x, y, c); });
  });
}

float BitmapTexture::eval_1(const SurfaceInteraction& si) const {
  Vec2 uv = to_uv_.apply(si.uv);
  if (texels_->channels() == 1) return lookup_channel(uv, 0);
  return lookup(uv).average();
}

template <TexelStorage::Format F>
Vec2 BitmapTexture::lookup_gradient_1(Vec2 uv) const {
  const TexelStorage& t = *texels_;
  // The same scalar as eval_1: channel 0 of grey images, else the mean of r, g, b.
  auto fetch = [&t](int x, int y) {
    return t.channels() == 1 ? t.at_as<F>(x, y, 0) : t.rgb_as<F>(x, y).average();
  };
  const float w = float(t.width()), h = float(t.height());
  float u = uv.x * w, v = uv.y * h;
  if (!(std::abs(u) < 1e9f) || !(std::abs(v) < 1e9f)) return {};
  u -= 0.5f;
  v -= 0.5f;
  float fx = std::floor(u), fy = std::floor(v);
  int x = int(fx), y = int(fy);
  float dx = u - fx, dy = v - fy;
  float p00 = texel<float>(x, y, fetch), p10 = texel<float>(x + 1, y, fetch);
  float p01 = texel<float>(x, y + 1, fetch), p11 = texel<float>(x + 1, y + 1, fetch);
  // d/du of the bilinear blend; the texel spacing is 1/w in u and 1/h in v.
  return {((p10 - p00) * (1.f - dy) + (p11 - p01) * dy) * w, ((p01 - p00) * (1.f - dx) + (p11 - p10) * dx) * h};
}

Vec2 BitmapTexture::eval_1_gradient(const SurfaceInteraction& si) const {
  if (filter_ == TextureFilter::Nearest) return to_uv_.pull_back({});
  const Vec2 uv = to_uv_.apply(si.uv);
  return to_uv_.pull_back(texels_->visit([&](auto format) { return lookup_gradient_1<decltype(format)::value>(uv); }));
}

TextureMemory texture_memory(const std::vector<std::shared_ptr<Texture>>& textures) {
  TextureMemory m;
  std::set<const TexelStorage*> seen;
  for (const auto& t : textures) {
    const auto* b = dynamic_cast<const BitmapTexture*>(t.get());
    if (!b || !seen.insert(b->texels().get()).second) continue;
    m.bytes += b->texels()->bytes();
    m.float_bytes += b->texels()->float_bytes();
    ++m.images;
  }
  return m;
}

namespace {

WrapMode read_wrap_mode(const SceneNode& node, const std::string& name, const std::string& def) {
  std::string value = node.get_string(name, def);
  std::transform(value.begin(), value.end(), value.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  if (auto mode = parse_wrap_mode(value)) return *mode;
  const Property* p = node.find(name);
  throw SceneError(p ? p->loc : node.loc, node.describe() + ": unknown " + name + " '" + value +
                                              "' (repeat, mirror, clamp, zero/black, one/white)");
}

TextureFilter read_filter(const SceneNode& node) {
  const Property* p = node.find("filter_type");
  if (!p || p->type != PropType::String) {
    node.get_string("filter_type", "");  // a wrongly typed value is reported by the getter
    return TextureFilter::Bilinear;
  }
  std::string value = p->s;
  std::transform(value.begin(), value.end(), value.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  if (value == "nearest") {
    p->used = true;
    return TextureFilter::Nearest;
  }
  if (value == "bilinear") {
    p->used = true;
    return TextureFilter::Bilinear;
  }
  // Left unread on purpose: the loader notes ewa/trilinear once per scene as image-neutral
  // (evaluated bilinearly, without MIP maps), and reports any other value as unsupported.
  if (value == "ewa" || value == "trilinear") return TextureFilter::Bilinear;
  throw SceneError(p->loc, node.describe() + ": unknown filter_type '" + p->s +
                               "' (ewa, trilinear, bilinear, nearest)");
}

}  // namespace

std::shared_ptr<Texture> make_bitmap(const SceneNode& node, LoadContext& ctx) {
  const Property* file = node.find("filename");
  if (!file) throw SceneError(node.loc, node.describe() + " needs a 'filename'");
  std::string name = node.get_string("filename", "");
  std::string path = ctx.resolve_path(name, file->loc);

  float gamma = node.get_float("gamma", 0.f);
  if (!(gamma == 0.f || gamma == -1.f || (gamma > 0.f && std::isfinite(gamma))))
    throw SceneError(node.find("gamma")->loc,
                     node.describe() + ": gamma must be -1 (sRGB) or positive, got " + std::to_string(gamma));
  bool raw = node.get_bool("raw", false);

  // wrap_mode first, so a bad value is reported under its own name and line.
  WrapMode wrap = read_wrap_mode(node, "wrap_mode", "repeat");
  WrapMode wrap_u = node.has("wrap_mode_u") ? read_wrap_mode(node, "wrap_mode_u", "") : wrap;
  WrapMode wrap_v = node.has("wrap_mode_v") ? read_wrap_mode(node, "wrap_mode_v", "") : wrap;
  TextureFilter filter = read_filter(node);
  UvMapping to_uv(node.get_transform("to_uv", Transform()));

  // Mitsuba 0.6's `channel`: one channel of the image as a monochrome texture (how a scene takes
  // a mask from an alpha channel; without it, an RGBA image is its RGB, as in Mitsuba).
  std::string channel = node.get_string("channel", "");
  std::transform(channel.begin(), channel.end(), channel.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  const int channel_index = channel.empty() ? -1 : channel == "r" ? 0 : channel == "g" ? 1 : channel == "b" ? 2
                                                                   : channel == "a" ? 3 : -2;
  if (channel_index == -2)
    throw SceneError(node.find("channel")->loc, node.describe() + ": unknown channel '" + channel + "' (r, g, b, a)");

  const BitmapDecodeSettings settings{gamma, raw, channel_index};
  const std::string key = bitmap_cache_key(path, settings);
  // Decoded in the background since the load began (bitmap_prefetch.h), unless the look-ahead
  // missed this one or could not read it: then here, where an error can name the scene's line.
  if (!ctx.has_resource<DecodedBitmap>(key))
    if (const BitmapPrefetch* ahead = bitmap_prefetch(ctx))
      if (auto d = ahead->get(key)) ctx.add_resource(key, std::move(d));
  std::shared_ptr<const DecodedBitmap> decoded = ctx.cached_resource<DecodedBitmap>(key, [&] {
    try {
      return decode_bitmap_file(path, settings);
    } catch (const SceneError& e) {
      // The reader names the file; the scene location says which texture wanted it.
      throw SceneError(file->loc, node.describe() + ": " + e.what());
    }
  });
  if (decoded->nonfinite && ctx.first_time("non-finite texels|" + key))
    ctx.warn(file->loc, node.describe() + ": " + std::to_string(decoded->nonfinite) +
                            " non-finite texel value(s) in '" + name + "' read as 0");
  // Shares the cache entry's ownership, pointing at its texels.
  std::shared_ptr<const TexelStorage> texels(decoded, &decoded->texels);
  return std::make_shared<BitmapTexture>(std::move(texels), wrap_u, wrap_v, filter, to_uv);
}

}  // namespace tessera
