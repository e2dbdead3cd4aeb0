// Light tracing units (bdpt.h): light subpaths connected to the camera (t = 1) and splatted onto
// the window through the pixel filter.
#include "render/bdpt_subpath.h"
#include "render/octahedral.h"

#include "tessera/core/check.h"
#include "tessera/render/render_tile.h"

#include <algorithm>
#include <cmath>

namespace tessera {

void LightSplats::reset(const TileRect& window, int full_width, int full_height) {
  TESSERA_CHECK(!window.empty());
  window_ = window;
  // The camera's importance integrates to 1 over the whole film, and the pass traces one light
  // path per window pixel and sample: this scale makes (splat sum / paths per pixel) the image.
  scale_ = double(full_width) * double(full_height) / double(window.area());
  sums_.assign(size_t(window.area()) * 3, 0.0);
  is_touched_.assign(size_t(window.area()), 0);
  touched_.clear();
  counters = {};
}

void LightSplats::add_pixel(int x, int y, double r, double g, double b) {
  const uint32_t i = uint32_t(size_t(y - window_.y0) * size_t(window_.width()) + size_t(x - window_.x0));
  if (!is_touched_[i]) {
    is_touched_[i] = 1;
    touched_.push_back(i);
  }
  double* s = &sums_[size_t(i) * 3];
  s[0] += r;
  s[1] += g;
  s[2] += b;
}

void LightSplats::add(Vec2 raster, Rgb value, const Filter* filter) {
  if (!value.is_finite()) {
    ++counters.nonfinite;
    return;
  }
  const float radius = filter ? filter->radius() : 0.5f;
  // Pixel i's centre is i + 0.5; the filter reaches the pixels whose centre is within its radius.
  const int x_lo = std::max(window_.x0, int(std::floor(raster.x - 0.5f - radius)));
  const int x_hi = std::min(window_.x1 - 1, int(std::ceil(raster.x - 0.5f + radius)));
  const int y_lo = std::max(window_.y0, int(std::floor(raster.y - 0.5f - radius)));
  const int y_hi = std::min(window_.y1 - 1, int(std::ceil(raster.y - 0.5f + radius)));
  for (int y = y_lo; y <= y_hi; ++y)
    for (int x = x_lo; x <= x_hi; ++x) {
      const Vec2 offset(raster.x - (float(x) + 0.5f), raster.y - (float(y) + 0.5f));
      float w = 0.f;
      if (filter) w = filter->eval(offset);
      else if (std::abs(offset.x) < 0.5f && std::abs(offset.y) < 0.5f) w = 1.f;
      if (!(w > 0.f)) continue;
      const double k = double(w) * scale_;
      add_pixel(x, y, value.r * k, value.g * k, value.b * k);
    }
}

std::vector<uint32_t> LightSplats::sorted_touched() const {
  std::vector<uint32_t> out = touched_;
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// t = 1 at one light vertex: its importance from the camera, MIS-weighted (bdpt) against the
// camera's subpath sampling this vertex (t >= 2).
void connect_to_camera(const Scene& scene, const bdpt::Vertex& v, float time, bool weighted, LightSplats& out) {
  CameraSampleWi cs;
  if (!scene.camera->sample_wi(v.si.p, v.u_lens, time, cs) || !(cs.pdf > 0.f)) return;
  const Rgb f = adjoint_eval(v.si, *v.bsdf, v.wo_world, cs.wi);
  if (f.is_black() || cs.we.is_black()) return;
  float w = 1.f;
  if (weighted && (scene.integrator.only_s < 0 || scene.integrator.only_weighted)) {
    Ray from_camera{cs.p_lens, -cs.wi};
    from_camera.time = time;
    float pdf_pos = 0.f, pdf_dir = 0.f;
    scene.camera->pdf_we(from_camera, pdf_pos, pdf_dir);
    const float camera_pdf_a = pdf_dir * std::abs(dot(v.si.ng, cs.wi)) / (cs.dist * cs.dist);
    const float pdf_rev = v.bsdf->pdf(v.si, v.si.to_local(cs.wi), v.wo);
    w = 1.f / (1.f + bdpt::mis(camera_pdf_a) * (v.d_vcm + v.d_vc * bdpt::mis(pdf_rev) + v.vm));
  }
  Ray shadow = spawn_ray_to(v.si, cs.p_lens, Vec3(0.f), Vec3(0.f));
  shadow.time = time;
  ++out.counters.shadow_rays;
  const float tr = scene.transmittance(shadow);
  if (!(tr > 0.f)) return;
  out.add(cs.raster, v.beta * f * cs.we * (tr * w / cs.pdf), scene.film.filter.get());
}

// A light vertex as vertex merging keeps it.
LightVertexRecord vertex_record(const bdpt::Vertex& v) {
  LightVertexRecord r;
  for (int c = 0; c < 3; ++c) {
    r.p[c] = v.si.p[c];
    r.beta[c] = v.beta[c];
  }
  r.wo = octahedral::encode(v.wo_world, 16);
  bdpt::encode_record_normal(v.si.ng, v.wo_world, r.n);
  r.length = uint16_t(std::min(v.length, 0xFFFF));
  r.d_vcm = v.d_vcm;
  r.d_vm = v.d_vm;
  return r;
}

// bdpt's and vcm's light paths: their light tracing and (vcm) their vertices.
void trace_paths(const Scene& scene, const VcmIteration& it, uint64_t path_begin, uint64_t path_end, uint32_t seed,
                 LightSplats& out, std::vector<LightVertexRecord>* records) {
  TESSERA_CHECK(scene.camera != nullptr);
  const IntegratorSettings& s = scene.integrator;
  const TileRect& window = out.window();
  const uint64_t pixels = uint64_t(window.area());
  const bool weighted = s.type == IntegratorType::Bdpt || s.type == IntegratorType::Vcm;
  const bool splats = traces_light_paths(s);
  const bdpt::MisWeights mw = bdpt::vcm_weights(s, it);
  Sampler sampler(scene.sampler.type, seed);
  thread_local bdpt::LightSubpath light;
  for (uint64_t k = path_begin; k < path_end; ++k) {
    // Path k is sample k / pixels of window pixel k mod pixels (PassSpec::same_samples).
    const uint64_t i = k % pixels;
    const Vec2i pixel{window.x0 + int(i % uint64_t(window.width())), window.y0 + int(i / uint64_t(window.width()))};
    sampler.start_pixel_sample(pixel, uint32_t(k / pixels));
    const float time = camera_sample_time(scene, sampler);
    ++out.counters.samples;
    if (s.max_depth == 0) continue;
    bdpt::trace_light_subpath(scene, s, sampler, time, light, out.counters, mw);
    for (const bdpt::Vertex& v : light.vertices) {
      if (s.max_depth >= 0 && v.length + 1 > s.max_depth) break;
      if (records && v.vm > 0.f) records->push_back(vertex_record(v));  // (where merges happen)
      if (splats && bdpt::strategy_weight(s, v.length + 1, 1, 1.f) > 0.f) connect_to_camera(scene, v, time, weighted, out);
    }
  }
}

}  // namespace

void trace_light_paths(const Scene& scene, uint64_t path_begin, uint64_t path_end, uint32_t seed, LightSplats& out) {
  trace_paths(scene, VcmIteration{}, path_begin, path_end, seed, out, nullptr);
}

void trace_vcm_light_paths(const Scene& scene, const VcmIteration& it, uint64_t path_begin, uint64_t path_end,
                           uint32_t seed, LightSplats& splats, std::vector<LightVertexRecord>& records) {
  trace_paths(scene, it, path_begin, path_end, seed, splats, &records);
}

}  // namespace tessera
