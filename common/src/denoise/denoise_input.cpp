#include "tessera/denoise/denoiser.h"

#include "tessera/core/error.h"

#include <stdexcept>

namespace tessera {
namespace {

Image* slot(DenoiseInput& in, AovLayer layer) {
  switch (layer) {
    case AovLayer::Albedo: return &in.albedo;
    case AovLayer::Normal: return &in.normal;
    case AovLayer::Depth: return &in.depth;
    case AovLayer::Variance: return &in.variance;
    case AovLayer::HalfA: return &in.half_a;
    case AovLayer::HalfB: break;
  }
  return &in.half_b;
}

}  // namespace

std::vector<ImageLayer> denoise_input_layers(const DenoiseInput& in) {
  std::vector<ImageLayer> layers;
  for (AovLayer l : denoise_layers())
    layers.push_back({aov_layer_name(l), aov_channel_names(l), *slot(const_cast<DenoiseInput&>(in), l)});
  return layers;
}

DenoiseInput make_denoise_input(const Image& color, const std::vector<ImageLayer>& layers) {
  DenoiseInput in;
  in.color = color.channels() == 3 ? color : color.to_rgb();
  for (AovLayer needed : denoise_layers()) {
    const ImageLayer* found = nullptr;
    for (const auto& l : layers) found = l.name == aov_layer_name(needed) ? &l : found;
    if (!found) throw std::invalid_argument(std::string("no AOV layer '") + aov_layer_name(needed) + "'");
    if (found->image.width() != color.width() || found->image.height() != color.height())
      throw std::invalid_argument(std::string("AOV layer '") + found->name + "' is " +
                                  std::to_string(found->image.width()) + "x" + std::to_string(found->image.height()) +
                                  ", the image " + std::to_string(color.width()) + "x" + std::to_string(color.height()));
    *slot(in, needed) = found->image;
  }
  return in;
}

DenoiseInput read_denoise_input(const std::string& path, ImageAttributes* attributes) {
  const Image color = read_exr(path, attributes);
  std::vector<ImageLayer> layers;
  std::string missing;
  for (AovLayer l : denoise_layers()) {
    try {
      layers.push_back({aov_layer_name(l), aov_channel_names(l), read_exr_layer(path, aov_layer_name(l), aov_channel_names(l))});
    } catch (const SceneError&) {
      missing += std::string(missing.empty() ? "" : ", ") + aov_layer_name(l);
    }
  }
  if (!missing.empty())
    throw SceneError(path + ": the denoiser needs the AOV layers albedo, normal, depth, variance, half_a, half_b; "
                     "missing: " + missing + " (render with --aovs all)");
  return make_denoise_input(color, layers);
}

}  // namespace tessera
