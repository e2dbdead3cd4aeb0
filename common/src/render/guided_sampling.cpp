#include "tessera/render/guided_sampling.h"

#include <algorithm>

namespace tessera {

namespace {

// At `square`, the point of wi on the guide's square.
MixturePdfs mixture_pdfs(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, Vec3 wi, Vec2 square,
                         const DirectionalTree& guide) {
  return {bsdf.pdf(si, wo, wi), guide.pdf_at(square), square};
}

float mix(const MixturePdfs& p, float bsdf_fraction) {
  return bsdf_fraction * p.bsdf + (1.f - bsdf_fraction) * p.guide;
}

}  // namespace

float guided_pdf(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, Vec3 wi, const DirectionalTree& guide,
                 float bsdf_fraction) {
  if (bsdf_fraction >= 1.f) return bsdf.pdf(si, wo, wi);  // (the guide's term is zero: no descent)
  return mix(mixture_pdfs(bsdf, si, wo, wi, direction_to_square(si.to_world(wi)), guide), bsdf_fraction);
}

bool sample_guided(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, const DirectionalTree& guide,
                   float bsdf_fraction, float u_lobe, Vec2 u_dir, BsdfSample& out, MixturePdfs* parts) {
  Vec2 square;
  MixturePdfs pdfs;
  if (u_lobe < bsdf_fraction) {
    // (u_lobe / bsdf_fraction is uniform in [0,1) again: the BSDF's own lobe choice.)
    const float u = std::min(u_lobe / bsdf_fraction, 1.f - 0x1p-24f);
    if (!bsdf.sample(si, wo, u, u_dir, out)) return false;
    if (out.delta) {
      out.pdf *= bsdf_fraction;
      out.weight *= 1.f / bsdf_fraction;
      return true;
    }
    square = direction_to_square(si.to_world(out.wi));
    if (bsdf_fraction >= 1.f) {
      // The mixture is the BSDF's own sampling, whose pdf and weight stand; the guide's density
      // is only asked for the parts.
      if (parts) *parts = {out.pdf, guide.pdf_at(square), square};
      return true;
    }
    pdfs = mixture_pdfs(bsdf, si, wo, out.wi, square, guide);
  } else {
    // The guide's density at the point it drew (pdf_at() there, without its descent), not at the
    // direction mapped back (which differs only where rounding crosses a cell's edge, and would
    // cost an arc tangent).
    out.wi = si.to_local(guide.sample(u_dir, pdfs.guide, &square));
    out.eta = 1.f;
    out.delta = false;
    pdfs.bsdf = bsdf.pdf(si, wo, out.wi);
    pdfs.square = square;
  }
  if (parts) *parts = pdfs;
  out.pdf = mix(pdfs, bsdf_fraction);
  if (!(out.pdf > 0.f)) return false;
  out.weight = bsdf.eval(si, wo, out.wi) * (1.f / out.pdf);  // (black where the BSDF has nothing)
  return true;
}

}  // namespace tessera
