// Baking Mitsuba 0.5/0.6's sun and sky into a latitude-longitude map for EnvmapLight
// (data/sunsky SPEC §6-7), adapted to Tessera's texel placement.
//
// Mitsuba bakes W x H pixels, H = floor(W / 2), with pixel centres at theta_j = (j + 1/2) pi / H and
// looks them up bilinearly about those centres. Tessera's EnvmapLight (light/envmap.h) puts row y at
// theta = pi y / (H' - 1) and column x at phi = 2 pi (x + 1/2) / W. Re-sampling Mitsuba's pixels onto
// that grid would add a second bilinear blur, so instead the sky is evaluated directly at our texel
// positions: with H' = floor(W / 2) + 1 rows the row spacing equals Mitsuba's pixel height, the
// looked-up radiance is exact at every texel and bilinear in between, i.e. as close to the model as a
// bilinear map of Mitsuba's density can be (and the poles are represented exactly). A texel exactly
// on the (stretched) horizon gets the model's limit from above rather than 0: above the horizon the
// map then matches the model everywhere, and the one-row leak below it (0.7 deg at W = 512) is what
// Mitsuba's own bilinear lookup shows too (its first dark pixel centre is half a row lower).
//
// The sun is splatted as Mitsuba does (same sample count, same (0,2)-sequence directions in the cone),
// but each sample is spread over the four texels the bilinear lookup would read, with weights
// divided by the exact solid angle of the texels' bilinear hat functions, so that the looked-up map
// integrates to exactly the requested irradiance over the sphere (Mitsuba: nearest pixel, with a
// sin(theta) approximation of the pixel's solid angle).
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/image/image.h"
#include "tessera/light/sunsky/hosek_sky.h"

#include <cstddef>

namespace tessera {

/// Rows of the baked map for Mitsuba's `resolution` (= the width): floor(resolution / 2) + 1.
int sunsky_map_height(int resolution);

/// Sky radiance times `sky_scale` at every texel of a width x height map (light space, Y-up);
/// `sun_phi` is the sun's azimuth, `stretch` Mitsuba's sky stretch in [1, 2].
Image bake_sky_map(const HosekSky& sky, double sun_phi, double stretch, float sky_scale, int width, int height);

/// Solid angle weight of texel row `y`: the integral over the sphere of the bilinear hat function of
/// one texel of that row (2 pi / W times the integral of the row's tent times sin theta).
double sunsky_texel_solid_angle(int y, int width, int height);

/// Mitsuba's number of splat samples: max(100, floor(res^2 / 2) * (1 - cos psi) / 2 * 1000).
size_t sun_splat_sample_count(int resolution, double cone_half_angle);

/// Adds a disk of half-angle `cone_half_angle` around the unit light-space direction `sun_dir`
/// whose looked-up radiance integrates to `irradiance` over the sphere.
void splat_sun(Image& map, Vec3 sun_dir, double cone_half_angle, Rgb irradiance, int resolution);

}  // namespace tessera
