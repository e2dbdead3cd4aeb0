// Named measured media: the `material` presets of Mitsuba 0.5/0.6's `homogeneous` medium and `dipole`
// subsurface plugins (Mitsuba 3 has no presets; its `homogeneous` takes only albedo/sigma_t/scale).
//
// Quantity and units, exactly as Mitsuba 0.6 stores them (src/medium/materials.h):
//   - Values are linear RGB triples in INVERSE MILLIMETRES (Mitsuba's plugin docs, table
//     "medium-coefficients"). They are RGB in the source, so an RGB build uses them unchanged.
//   - `sigma_s` is the REDUCED scattering coefficient sigma_s' = sigma_s * (1 - g). Jensen et al. 2001
//     only published sigma_s' (Mitsuba stores it with g = 0); Narasimhan et al. 2006 rows are stored
//     by Mitsuba as sigma_s plus an RGB g, but both Mitsuba consumers (Medium's constructor and
//     dipole's configure()) immediately fold g in and use sigma_s * (1 - g) with an isotropic phase
//     function by default. The folded value is returned here, so a renderer using these numbers with
//     an isotropic phase function matches Mitsuba 0.6.
//   - `eta` is the relative index of refraction from the table (dipole uses it when neither
//     int_ior nor ext_ior is given; the homogeneous medium ignores it).
//
// Reproducing Mitsuba 0.6 (read this before wiring up a factory):
//   - lookupMaterial() multiplies the table by 100 (kMitsuba06PresetFactor) and then by `scale`
//     (default 1), although the docs say the presets are per millimetre and `scale` alone should
//     correct units. So Mitsuba 0.6 renders sigma = table * 100 * scale per scene unit.
//   - The preset is ALWAYS looked up, with default name "Skin1": user sigmaS/sigmaA (or
//     sigmaT/albedo) override it per parameter, so a medium declaring only sigmaA gets Skin1's
//     sigma_s * 100. Giving both `material` and any sigma* parameter is an error.
//   - Name matching: both sides lower-cased, otherwise exact (spaces and '&' significant, no
//     trimming). An unknown name is an error listing all names.
#pragma once

#include "tessera/core/rgb.h"

#include <string>
#include <string_view>
#include <vector>

namespace tessera {

/// Factor Mitsuba 0.6's lookupMaterial() applies to every preset before `scale`.
inline constexpr float kMitsuba06PresetFactor = 100.f;

struct MeasuredMedium {
  Rgb sigma_s;      // reduced scattering coefficient sigma_s' = sigma_s (1 - g), 1/mm
  Rgb sigma_a;      // absorption coefficient, 1/mm
  float eta = 1.f;  // relative index of refraction listed with the preset
};

/// Case-insensitive (ASCII) lookup by Mitsuba preset name, e.g. "skin1", "Lowfat Milk". Also accepts
/// the spellings of Mitsuba's documentation where its code differs ("Budweiser Beer", "Suisse Mocha").
/// Returns false and leaves `out` untouched for an unknown name.
bool lookup_measured_medium(std::string_view name, MeasuredMedium& out);

/// The preset names in table order, spelled as Mitsuba 0.6's code spells them (for error messages).
std::vector<std::string> measured_medium_names();

}  // namespace tessera
