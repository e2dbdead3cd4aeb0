// Named indices of refraction (Mitsuba 0.6's table, src/bsdfs/ior.h: Hecht, Optics, ~589 nm) and the
// `int_ior` / `ext_ior` parameter convention shared by dielectric-like BSDFs: a number, or a name.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace tessera {

struct SceneNode;

/// IOR of a named material, case-insensitive ("BK7" == "bk7"); nullopt if unknown.
std::optional<float> lookup_ior(std::string_view name);

/// The known names, comma separated, in table order (for error messages).
std::string known_ior_names();

/// Reads parameter `name` of `node` as a float or a material name; absent -> the IOR of
/// `default_name`. An unknown name throws SceneError at the property's file:line listing the known
/// names. Marks the property used.
float read_ior(const SceneNode& node, const std::string& name, std::string_view default_name);

}  // namespace tessera
