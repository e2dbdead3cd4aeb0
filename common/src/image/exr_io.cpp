// OpenEXR through the general FrameBuffer API, so that half and float channels, tiled files and
// data windows not at the origin are all read the same way.
#include "tessera/image/image.h"
#include "tessera/image/packed_image.h"

#include "image/io_util.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <charconv>
#include <climits>
#include <exception>
#include <set>

namespace tessera {

namespace {

using image_detail::fail;

// Header attributes OpenEXR defines or writes itself; user attributes must not shadow them.
const std::set<std::string>& reserved_attribute_names() {
  static const std::set<std::string> names = {
      "channels", "compression", "dataWindow", "displayWindow", "lineOrder", "pixelAspectRatio",
      "screenWindowCenter", "screenWindowWidth", "tiles", "type", "name", "chunkCount",
      "maxSamplesPerPixel"};
  return names;
}

bool parse_int32(const std::string& s, int& out) {
  if (s.empty()) return false;
  // A leading '+' or zero-padding would not survive a round trip, so keep such values as strings.
  if (s[0] == '+' || (s.size() > 1 && s[0] == '0') || (s.size() > 2 && s[0] == '-' && s[1] == '0'))
    return false;
  if (s == "-0") return false;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

// The data window's size, checked; and the channels to read (R,G,B[,A] or Y), checked.
struct ExrLayout {
  Imath::Box2i dw;
  int width = 0, height = 0;
  std::vector<std::string> names;
  bool all_half = true;  // every channel read is stored as half
};

ExrLayout exr_layout(const std::string& path, const Imf::Header& header) {
  ExrLayout out;
  out.dw = header.dataWindow();
  const Imath::Box2i& dw = out.dw;
  long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > INT_MAX / 4 || h > INT_MAX / 4 || w * h > (1LL << 31))
    fail(path, "EXR data window is empty or too large");
  out.width = int(w), out.height = int(h);

  const Imf::ChannelList& ch = header.channels();
  bool has_r = ch.findChannel("R"), has_g = ch.findChannel("G"), has_b = ch.findChannel("B");
  bool has_a = ch.findChannel("A"), has_y = ch.findChannel("Y");
  if (has_r || has_g || has_b) {
    if (!(has_r && has_g && has_b)) fail(path, "EXR has only some of the channels R, G, B");
    out.names = {"R", "G", "B"};
    if (has_a) out.names.push_back("A");
  } else if (has_y) {
    out.names = {"Y"};  // a luminance image: alpha, if any, is dropped
  } else {
    std::string found;
    for (auto it = ch.begin(); it != ch.end(); ++it) found += std::string(found.empty() ? "" : ", ") + it.name();
    fail(path, "EXR has no R,G,B or Y channels (found: " + (found.empty() ? "none" : found) + ")");
  }
  for (const auto& n : out.names) {
    const Imf::Channel* c = ch.findChannel(n);
    if (c->xSampling != 1 || c->ySampling != 1) fail(path, "EXR channel " + n + " is subsampled (unsupported)");
    if (c->type != Imf::HALF) out.all_half = false;
  }
  return out;
}

}  // namespace

Image read_exr(const std::string& path, ImageAttributes* attributes) {
  image_detail::require_readable_file(path);
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const ExrLayout layout = exr_layout(path, header);
    const Imath::Box2i& dw = layout.dw;
    const std::vector<std::string>& names = layout.names;
    const size_t w = size_t(layout.width);
    const int h = layout.height;

    Image img(int(w), h, int(names.size()));
    Imf::FrameBuffer fb;
    size_t xstride = sizeof(float) * names.size(), ystride = xstride * size_t(w);
    for (size_t c = 0; c < names.size(); ++c)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, img.data() + c, dw, xstride, ystride));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);

    if (attributes) {
      attributes->clear();
      for (auto it = header.begin(); it != header.end(); ++it) {
        if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
          (*attributes)[it.name()] = s->value();
        else if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&it.attribute()))
          (*attributes)[it.name()] = std::to_string(i->value());
      }
    }
    return img;
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read EXR: ") + e.what());
  }
}

PackedImage read_exr_packed(const std::string& path) {
  image_detail::require_readable_file(path);
  try {
    Imf::InputFile file(path.c_str());
    const ExrLayout layout = exr_layout(path, file.header());
    PackedImage img;
    img.width = layout.width, img.height = layout.height, img.channels = int(layout.names.size());
    // Half files stay half; anything else (float, uint) is read as float, as read_exr does.
    img.format = layout.all_half ? PixelFormat::Half : PixelFormat::F32;
    const size_t value_size = layout.all_half ? sizeof(uint16_t) : sizeof(float);
    char* base;
    if (layout.all_half) {
      img.u16.resize(img.num_values());
      base = reinterpret_cast<char*>(img.u16.data());
    } else {
      img.f32.resize(img.num_values());
      base = reinterpret_cast<char*>(img.f32.data());
    }
    Imf::FrameBuffer fb;
    const size_t xstride = value_size * layout.names.size(), ystride = xstride * size_t(layout.width);
    for (size_t c = 0; c < layout.names.size(); ++c)
      fb.insert(layout.names[c], Imf::Slice::Make(layout.all_half ? Imf::HALF : Imf::FLOAT, base + c * value_size,
                                                  layout.dw, xstride, ystride));
    file.setFrameBuffer(fb);
    file.readPixels(layout.dw.min.y, layout.dw.max.y);
    return img;
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read EXR: ") + e.what());
  }
}

namespace {

// One channel to write: its full name and where its values are (every `stride` floats).
struct OutChannel {
  std::string name;
  const float* first;
  size_t stride;
};

void write_channels(const std::string& path, int width, int height, const std::vector<OutChannel>& channels,
                    const ImageAttributes& attributes) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
  for (const auto& [key, value] : attributes) {
    if (key.empty() || reserved_attribute_names().count(key))
      fail(path, "EXR attribute name '" + key + "' is empty or reserved");
    int iv = 0;
    if (parse_int32(value, iv)) header.insert(key, Imf::IntAttribute(iv));
    else header.insert(key, Imf::StringAttribute(value));
  }
  try {
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer fb;
    for (const auto& c : channels) {
      const size_t xstride = sizeof(float) * c.stride;
      // OpenEXR's Slice takes a non-const pointer even for output.
      char* base = reinterpret_cast<char*>(const_cast<float*>(c.first));
      fb.insert(c.name, Imf::Slice(Imf::FLOAT, base, xstride, xstride * size_t(width)));
    }
    file.setFrameBuffer(fb);
    file.writePixels(height);
  } catch (const std::exception& e) {
    fail(path, std::string("cannot write EXR: ") + e.what());
  }
}

// The channels of `image`, named `prefix` + names[c].
void add_channels(std::vector<OutChannel>& out, const Image& image, const std::string& prefix,
                  const std::vector<std::string>& names) {
  for (int c = 0; c < image.channels(); ++c)
    out.push_back({prefix + names[size_t(c)], image.data() + c, size_t(image.channels())});
}

const std::vector<std::string>& beauty_channel_names(int channels) {
  static const std::vector<std::string> kNames[3] = {{"Y"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  return kNames[channels == 1 ? 0 : (channels == 3 ? 1 : 2)];
}

}  // namespace

void write_exr(const std::string& path, const Image& image_in, const ImageAttributes& attributes) {
  write_exr_layers(path, image_in, {}, attributes);
}

void write_exr_layers(const std::string& path, const Image& beauty_in, const std::vector<ImageLayer>& layers,
                      const ImageAttributes& attributes) {
  if (beauty_in.empty()) fail(path, "cannot write an empty image");
  const Image beauty = beauty_in.srgb_encoded() ? beauty_in.linearized() : beauty_in;
  std::vector<OutChannel> channels;
  add_channels(channels, beauty, "", beauty_channel_names(beauty.channels()));
  for (const auto& layer : layers) {
    TESSERA_CHECK(layer.image.width() == beauty.width() && layer.image.height() == beauty.height() &&
                  size_t(layer.image.channels()) == layer.channels.size());
    add_channels(channels, layer.image, layer.name + ".", layer.channels);
  }
  write_channels(path, beauty.width(), beauty.height(), channels, attributes);
}

Image read_exr_layer(const std::string& path, const std::string& name, const std::vector<std::string>& channels) {
  image_detail::require_readable_file(path);
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > INT_MAX / 4 || h > INT_MAX / 4 || w * h > (1LL << 31))
      fail(path, "EXR data window is empty or too large");
    std::string missing;
    for (const auto& c : channels)
      if (!header.channels().findChannel(name + "." + c)) missing += (missing.empty() ? "" : ", ") + name + "." + c;
    if (!missing.empty()) fail(path, "EXR has no layer '" + name + "' (missing channels: " + missing + ")");
    Image img(int(w), int(h), int(channels.size()));
    Imf::FrameBuffer fb;
    const size_t xstride = sizeof(float) * channels.size(), ystride = xstride * size_t(w);
    for (size_t c = 0; c < channels.size(); ++c)
      fb.insert(name + "." + channels[c], Imf::Slice::Make(Imf::FLOAT, img.data() + c, dw, xstride, ystride));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read EXR: ") + e.what());
  }
}

}  // namespace tessera
