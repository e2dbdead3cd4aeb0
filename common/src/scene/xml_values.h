// Internal to the scene parser: the value grammar of Mitsuba XML attributes (numbers, lists,
// colours, spectra, transform elements) as pure functions of an element's attribute values.
// The tree walk (xml_parser.cpp) gathers attributes after `$name` substitution and calls these.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/transform.h"
#include "tessera/core/vec.h"
#include "tessera/scene/error.h"
#include "tessera/scene/scene_desc.h"

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tessera::xml {

/// The attributes of one element after substitution, in document order.
struct Attrs {
  std::vector<std::pair<std::string, std::string>> items;
  const std::string* get(std::string_view name) const;
  /// Throws SceneError at `loc` naming `element` when the attribute is absent.
  const std::string& require(std::string_view name, std::string_view element, const FileLoc& loc) const;
  /// Throws SceneError for any attribute not in `allowed`.
  void check_allowed(std::initializer_list<std::string_view> allowed, std::string_view element,
                     const FileLoc& loc) const;
};

/// Splits on whitespace and commas ("1, 2 3" -> {"1","2","3"}).
std::vector<std::string_view> tokenize(std::string_view s);

/// Strict number parsing: the whole (trimmed) text must be one finite number within float range
/// (for doubles) or within int64 (for integers). `what` names the value in the message.
double parse_double(std::string_view text, const FileLoc& loc, std::string_view what);
int64_t parse_int(std::string_view text, const FileLoc& loc, std::string_view what);
bool parse_bool(std::string_view text, const FileLoc& loc, std::string_view what);
/// Exactly `n` numbers separated by commas and/or whitespace.
std::vector<double> parse_list(std::string_view text, size_t n, const FileLoc& loc, std::string_view what);

/// Mitsuba 3's upgrade of 0.x names: "toWorld" -> "to_world", "intIOR" -> "int_ior".
std::string camel_to_snake(std::string_view name);
/// Full normalisation of a parameter name of a plugin `tag`/`type` for a file of `version_major`:
/// camel_to_snake for 0.x plus the few irregular renames Mitsuba 3 applies.
std::string normalize_name(std::string_view written, int version_major, std::string_view parent_tag,
                           std::string_view parent_type);

/// Fills the typed part of `prop` for the property element `tag` (boolean, integer, float, string,
/// rgb, srgb, spectrum, blackbody, point, vector). `base_dir` resolves <spectrum filename=..>, which
/// must lie inside `root_dir` unless that is empty (ParseOptions::root_dir).
/// Returns false when `tag` is not one of these.
bool parse_value_property(std::string_view tag, const Attrs& attrs, const FileLoc& loc,
                          const std::string& base_dir, const std::string& root_dir, Property& prop);

/// One child of <transform> (translate, rotate, scale, matrix, lookat) as a matrix. Throws
/// SceneError for anything else or for malformed values.
Matrix4 parse_transform_element(std::string_view tag, const Attrs& attrs, const FileLoc& loc);

/// Spectral reductions (spectrum.cpp), Mitsuba 0.6 RGB-build semantics.
Rgb spectrum_to_rgb(const std::vector<double>& wavelengths, const std::vector<double>& values);
Rgb blackbody_to_rgb(double kelvin);

}  // namespace tessera::xml
