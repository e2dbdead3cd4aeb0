#include "tessera/farm/build_fingerprint.h"

#include "tessera/farm/sha256.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <cstring>

namespace tessera {
namespace {

// Exercises the paths whose bits depend on the compiler and ISA: triangle and sphere
// intersection, BVH, a rough and a smooth BSDF, area and point lights, the filter, the sampler.
constexpr const char* kProbeScene = R"(<scene version="0.6.0">
  <integrator type="path"><integer name="maxDepth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="toWorld"><lookat origin="0,1,-4" target="0,0.5,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
      <rfilter type="gaussian"/></film>
  </sensor>
  <shape type="rectangle">
    <transform name="toWorld"><rotate x="1" angle="-90"/><scale value="3"/></transform>
    <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf>
  </shape>
  <shape type="sphere"><point name="center" x="0" y="0.6" z="0"/><float name="radius" value="0.6"/>
    <bsdf type="dielectric"/></shape>
  <shape type="sphere"><point name="center" x="1" y="2" z="-1"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="8,7,6"/></emitter></shape>
  <emitter type="point"><point name="position" x="-1" y="2" z="0"/><rgb name="intensity" value="3"/></emitter>
</scene>)";

std::string isa_string() {
  std::string s;
#if defined(__x86_64__)
  s = "x86-64";
#elif defined(__aarch64__)
  s = "aarch64";
#else
  s = "unknown-arch";
#endif
#if defined(__AVX512F__)
  s += "+avx512f";
#elif defined(__AVX2__)
  s += "+avx2";
#elif defined(__SSE4_2__)
  s += "+sse4.2";
#endif
#if defined(__FMA__)
  s += "+fma";
#endif
#if defined(__clang__)
  s += " clang-" + std::to_string(__clang_major__);
#elif defined(__GNUC__)
  s += " gcc-" + std::to_string(__GNUC__);
#endif
  return s;
}

std::string probe_hash() {
  SceneDesc desc = parse_scene_string(kProbeScene, "<build probe>");
  LoadResult loaded = load_scene(desc, LoadOptions{});
  RenderSettings settings;
  settings.spp = loaded.scene->sampler.sample_count;
  settings.threads = 1;
  settings.seed = 7;
  Film film = render(*loaded.scene, settings);
  std::string bytes;
  for (int y = film.window().y0; y < film.window().y1; ++y)
    for (int x = film.window().x0; x < film.window().x1; ++x) {
      const PixelSums& p = film.pixel({x, y});
      bytes.append(reinterpret_cast<const char*>(p.sum), sizeof(p.sum));
      bytes.append(reinterpret_cast<const char*>(p.sum_sq), sizeof(p.sum_sq));
    }
  return sha256_hex(bytes);
}

}  // namespace

const BuildFingerprint& build_fingerprint() {
  static const BuildFingerprint fp{TESSERA_VERSION, isa_string(), probe_hash()};
  return fp;
}

std::string fingerprint_mismatch(const BuildFingerprint& mine, const BuildFingerprint& other) {
  if (other.version != mine.version)
    return "worker version " + other.version + " differs from the coordinator's " + mine.version +
           "; install the same Tessera release on every machine";
  if (other.probe != mine.probe)
    return "worker build (" + other.isa + ") renders different bits from the coordinator's (" + mine.isa +
           "): the probe render's hash " + other.probe.substr(0, 12) + " != " + mine.probe.substr(0, 12) +
           "; build every machine with the same compiler and flags";
  return {};
}

}  // namespace tessera
