// Fresnel reflectance for smooth interfaces. `cos_theta_i` is measured against the normal on the side
// the light arrives from when positive; a negative value means arriving from inside (the dielectric
// functions then use 1/eta). eta = n_inside / n_outside.
#pragma once

#include "tessera/core/rgb.h"

namespace tessera {

/// Unpolarised dielectric reflectance. Sets `cos_theta_t` to the cosine of the refracted direction,
/// with the sign opposite to cos_theta_i (0 under total internal reflection, where the result is 1).
float fresnel_dielectric(float cos_theta_i, float eta, float* cos_theta_t = nullptr);

/// Unpolarised conductor reflectance for complex IOR eta + i k, per channel; cos_theta_i >= 0.
Rgb fresnel_conductor(float cos_theta_i, Rgb eta, Rgb k);

}  // namespace tessera
