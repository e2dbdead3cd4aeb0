// Value grammar of Mitsuba XML attributes: strict numbers, lists, names, typed property elements.
#include "scene/xml_values.h"

#include "scene/path_confinement.h"

#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace tessera::xml {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

std::string squote(std::string_view s) { return "'" + std::string(s) + "'"; }

// "<tag>"; built by appending (GCC 12 warns falsely on "<" + std::string(...)).
std::string elem(std::string_view tag) {
  std::string s("<");
  s += tag;
  s += '>';
  return s;
}

}  // namespace

const std::string* Attrs::get(std::string_view name) const {
  for (const auto& [k, v] : items)
    if (k == name) return &v;
  return nullptr;
}

const std::string& Attrs::require(std::string_view name, std::string_view element,
                                  const FileLoc& loc) const {
  if (const std::string* v = get(name)) return *v;
  throw SceneError(loc, elem(element) + " is missing the attribute " + squote(name));
}

void Attrs::check_allowed(std::initializer_list<std::string_view> allowed, std::string_view element,
                          const FileLoc& loc) const {
  for (const auto& [k, v] : items) {
    bool ok = false;
    for (std::string_view a : allowed) ok = ok || (a == k);
    if (!ok)
      throw SceneError(loc, "unexpected attribute " + squote(k) + " in " + elem(element));
  }
}

std::vector<std::string_view> tokenize(std::string_view s) {
  std::vector<std::string_view> out;
  size_t i = 0;
  auto is_sep = [](char c) { return c == ',' || std::isspace(static_cast<unsigned char>(c)); };
  while (i < s.size()) {
    while (i < s.size() && is_sep(s[i])) ++i;
    size_t start = i;
    while (i < s.size() && !is_sep(s[i])) ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

double parse_double(std::string_view text, const FileLoc& loc, std::string_view what) {
  std::string_view t = trim(text);
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec == std::errc::invalid_argument || ptr != t.data() + t.size())
    throw SceneError(loc, "invalid number " + squote(text) + " for " + std::string(what));
  // from_chars accepts "inf"/"nan"; a scene value must be an ordinary float.
  if (ec == std::errc::result_out_of_range || !std::isfinite(v) || std::abs(v) > double(FLT_MAX))
    throw SceneError(loc, "number " + squote(text) + " for " + std::string(what) +
                              " is not a finite single-precision value");
  return v;
}

int64_t parse_int(std::string_view text, const FileLoc& loc, std::string_view what) {
  std::string_view t = trim(text);
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  int64_t v = 0;
  auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec == std::errc::invalid_argument || ptr != t.data() + t.size())
    throw SceneError(loc, "invalid integer " + squote(text) + " for " + std::string(what));
  if (ec == std::errc::result_out_of_range)
    throw SceneError(loc, "integer " + squote(text) + " for " + std::string(what) + " is out of range");
  return v;
}

bool parse_bool(std::string_view text, const FileLoc& loc, std::string_view what) {
  std::string t(trim(text));
  for (char& c : t) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (t == "true") return true;
  if (t == "false") return false;
  throw SceneError(loc, "invalid boolean " + squote(text) + " for " + std::string(what) +
                            " (expected 'true' or 'false')");
}

std::vector<double> parse_list(std::string_view text, size_t n, const FileLoc& loc, std::string_view what) {
  auto tokens = tokenize(text);
  if (tokens.size() != n)
    throw SceneError(loc, std::string(what) + " needs " + std::to_string(n) + " values, got " +
                              std::to_string(tokens.size()) + " in " + squote(text));
  std::vector<double> out;
  out.reserve(n);
  for (auto t : tokens) out.push_back(parse_double(t, loc, what));
  return out;
}

std::string camel_to_snake(std::string_view name) {
  // Mitsuba 3 (xml.cpp, upgrade_tree): an underscore before each lower->upper step, and the run of
  // capitals that follows is lower-cased, so "intIOR" becomes "int_ior" rather than "int_i_o_r".
  auto lower = [](char c) { return std::islower(static_cast<unsigned char>(c)) != 0; };
  auto upper = [](char c) { return std::isupper(static_cast<unsigned char>(c)) != 0; };
  std::string out;
  out.reserve(name.size() + 4);
  size_t i = 0;
  while (i < name.size()) {
    out += name[i];
    if (lower(name[i]) && i + 1 < name.size() && upper(name[i + 1])) {
      out += '_';
      for (++i; i < name.size() && upper(name[i]); ++i)
        out += char(std::tolower(static_cast<unsigned char>(name[i])));
      continue;
    }
    ++i;
  }
  return out;
}

std::string normalize_name(std::string_view written, int version_major, std::string_view parent_tag,
                           std::string_view parent_type) {
  if (version_major >= 2) return std::string(written);
  std::string n = camel_to_snake(written);
  // Irregular renames of the 0.x -> 3 upgrade. Mitsuba 0.6's diffuse and roughdiffuse accept
  // "diffuseReflectance" as a synonym of "reflectance"; Mitsuba 3 keeps only the latter.
  if (n == "diffuse_reflectance" && parent_tag == "bsdf" &&
      (parent_type == "diffuse" || parent_type == "roughdiffuse"))
    return "reflectance";
  return n;
}

namespace {

Rgb parse_rgb_triplet(std::string_view value, const FileLoc& loc, std::string_view what, bool srgb) {
  std::string_view v = trim(value);
  if (srgb && !v.empty() && v.front() == '#') {
    if (v.size() != 7) throw SceneError(loc, "invalid hex colour " + squote(value) + " for " + std::string(what));
    Rgb c;
    for (int i = 0; i < 3; ++i) {
      unsigned x = 0;
      auto [ptr, ec] = std::from_chars(v.data() + 1 + 2 * i, v.data() + 3 + 2 * i, x, 16);
      if (ec != std::errc() || ptr != v.data() + 3 + 2 * i)
        throw SceneError(loc, "invalid hex colour " + squote(value) + " for " + std::string(what));
      c[i] = srgb_to_linear(float(x) / 255.f);
    }
    return c;
  }
  auto tokens = tokenize(v);
  Rgb c;
  if (tokens.size() == 1) {
    c = Rgb(float(parse_double(tokens[0], loc, what)));
  } else if (tokens.size() == 3) {
    for (int i = 0; i < 3; ++i) c[i] = float(parse_double(tokens[i], loc, what));
  } else {
    throw SceneError(loc, std::string(what) + " needs 1 or 3 values, got " + std::to_string(tokens.size()) +
                              " in " + squote(value));
  }
  if (srgb)
    for (int i = 0; i < 3; ++i) c[i] = srgb_to_linear(c[i]);
  return c;
}

Rgb parse_spectrum_pairs(const std::vector<std::string_view>& tokens, const FileLoc& loc, std::string_view what) {
  std::vector<double> wl, val;
  for (auto t : tokens) {
    size_t colon = t.find(':');
    if (colon == std::string_view::npos)
      throw SceneError(loc, "mixed 'wavelength:value' and plain values in " + std::string(what));
    double l = parse_double(t.substr(0, colon), loc, what);
    double v = parse_double(t.substr(colon + 1), loc, what);
    if (l <= 0 || (!wl.empty() && l <= wl.back()))
      throw SceneError(loc, "wavelengths of " + std::string(what) + " must be positive and increasing");
    wl.push_back(l);
    val.push_back(v);
  }
  return spectrum_to_rgb(wl, val);
}

Rgb read_spectrum_file(const std::string& filename, const std::string& base_dir, const std::string& root_dir,
                       const FileLoc& loc, std::string_view what) {
  namespace fs = std::filesystem;
  fs::path p(filename);
  if (p.is_relative() && !base_dir.empty()) p = fs::path(base_dir) / p;
  if (!detail::inside_root(root_dir, p)) detail::throw_outside_root(loc, filename);
  std::ifstream in(p);
  if (!in) throw SceneError(loc, "cannot open spectrum file " + squote(filename));
  std::vector<double> wl, val;
  std::string line;
  FileLoc file_loc{p.string(), 0};
  while (std::getline(in, line)) {
    ++file_loc.line;
    std::string_view l = trim(line);
    if (l.empty() || l.front() == '#') continue;
    auto tokens = tokenize(l);
    if (tokens.size() != 2) throw SceneError(file_loc, "expected 'wavelength value'");
    double lambda = parse_double(tokens[0], file_loc, "wavelength");
    if (lambda <= 0 || (!wl.empty() && lambda <= wl.back()))
      throw SceneError(file_loc, "wavelengths must be positive and increasing");
    wl.push_back(lambda);
    val.push_back(parse_double(tokens[1], file_loc, what));
  }
  if (wl.empty()) throw SceneError(loc, "spectrum file " + squote(filename) + " holds no samples");
  return spectrum_to_rgb(wl, val);
}

Vec3 parse_xyz(const Attrs& attrs, const FileLoc& loc, std::string_view element, double def) {
  const std::string* value = attrs.get("value");
  if (value) {
    if (attrs.get("x") || attrs.get("y") || attrs.get("z"))
      throw SceneError(loc, elem(element) + " mixes 'value' with 'x'/'y'/'z'");
    auto tokens = tokenize(*value);
    if (tokens.size() == 1) return Vec3(float(parse_double(tokens[0], loc, element)));
    auto v = parse_list(*value, 3, loc, elem(element) + " value");
    return Vec3(float(v[0]), float(v[1]), float(v[2]));
  }
  Vec3 r{float(def)};
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
    if (const std::string* a = attrs.get(axes[i])) r[i] = float(parse_double(*a, loc, element));
  return r;
}

}  // namespace

bool parse_value_property(std::string_view tag, const Attrs& attrs, const FileLoc& loc,
                          const std::string& base_dir, const std::string& root_dir, Property& prop) {
  const std::string what = elem(tag) + " '" + prop.written_name + "'";
  if (tag == "boolean" || tag == "integer" || tag == "float" || tag == "string") {
    attrs.check_allowed({"name", "value"}, tag, loc);
    const std::string& value = attrs.require("value", tag, loc);
    if (tag == "boolean") {
      prop.type = PropType::Boolean;
      prop.b = parse_bool(value, loc, what);
    } else if (tag == "integer") {
      prop.type = PropType::Integer;
      prop.i = parse_int(value, loc, what);
    } else if (tag == "float") {
      prop.type = PropType::Float;
      prop.f = parse_double(value, loc, what);
    } else {
      prop.type = PropType::String;
      prop.s = value;
    }
    return true;
  }
  if (tag == "rgb" || tag == "srgb") {
    attrs.check_allowed({"name", "value", "intent"}, tag, loc);
    prop.type = PropType::Color;
    prop.color = parse_rgb_triplet(attrs.require("value", tag, loc), loc, what, tag == "srgb");
    return true;
  }
  if (tag == "spectrum") {
    attrs.check_allowed({"name", "value", "filename", "intent"}, tag, loc);
    prop.type = PropType::Color;
    const std::string* value = attrs.get("value");
    const std::string* filename = attrs.get("filename");
    if ((value != nullptr) == (filename != nullptr))
      throw SceneError(loc, what + " needs exactly one of 'value' and 'filename'");
    if (filename) {
      prop.color = read_spectrum_file(*filename, base_dir, root_dir, loc, what);
      return true;
    }
    auto tokens = tokenize(*value);
    if (!tokens.empty() && tokens[0].find(':') != std::string_view::npos)
      prop.color = parse_spectrum_pairs(tokens, loc, what);
    else
      prop.color = parse_rgb_triplet(*value, loc, what, false);  // 1 value: grey; 3: the RGB build's samples
    return true;
  }
  if (tag == "blackbody") {
    attrs.check_allowed({"name", "temperature", "scale"}, tag, loc);
    std::string_view t = trim(attrs.require("temperature", tag, loc));
    if (!t.empty() && (t.back() == 'K' || t.back() == 'k')) t.remove_suffix(1);
    double kelvin = parse_double(t, loc, what);
    if (!(kelvin > 0)) throw SceneError(loc, what + ": temperature must be positive");
    double scale = 1.0;
    if (const std::string* s = attrs.get("scale")) scale = parse_double(*s, loc, what);
    prop.type = PropType::Color;
    prop.color = blackbody_to_rgb(kelvin) * float(scale);
    if (!prop.color.is_finite()) throw SceneError(loc, what + " is not finite");
    return true;
  }
  if (tag == "point" || tag == "vector") {
    attrs.check_allowed({"name", "value", "x", "y", "z"}, tag, loc);
    prop.type = PropType::Vector;
    prop.v = parse_xyz(attrs, loc, tag, 0.0);
    return true;
  }
  return false;
}

Matrix4 parse_transform_element(std::string_view tag, const Attrs& attrs, const FileLoc& loc) {
  if (tag == "translate") {
    attrs.check_allowed({"value", "x", "y", "z"}, tag, loc);
    return Transform::translate(parse_xyz(attrs, loc, tag, 0.0)).matrix();
  }
  if (tag == "scale") {
    attrs.check_allowed({"value", "x", "y", "z"}, tag, loc);
    Vec3 s = parse_xyz(attrs, loc, tag, 1.0);
    Matrix4 m = Matrix4::identity();
    for (int i = 0; i < 3; ++i) m.m[i][i] = s[i];
    return m;
  }
  if (tag == "rotate") {
    attrs.check_allowed({"value", "x", "y", "z", "angle"}, tag, loc);
    Vec3 axis = parse_xyz(attrs, loc, tag, 0.0);
    double angle = parse_double(attrs.require("angle", tag, loc), loc, "<rotate> angle");
    if (axis == Vec3(0.f)) throw SceneError(loc, "<rotate> needs a non-zero axis");
    return Transform::rotate(axis, float(angle)).matrix();
  }
  if (tag == "matrix") {
    attrs.check_allowed({"value"}, tag, loc);
    const std::string& value = attrs.require("value", tag, loc);
    auto tokens = tokenize(value);
    if (tokens.size() != 16 && tokens.size() != 9)
      throw SceneError(loc, "<matrix> needs 16 values (or 9 for a 3x3 matrix), got " +
                                std::to_string(tokens.size()));
    Matrix4 m = Matrix4::identity();
    int n = tokens.size() == 16 ? 4 : 3;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) m.m[r][c] = parse_double(tokens[r * n + c], loc, "<matrix> value");
    return m;
  }
  if (tag == "lookat" || tag == "lookAt") {
    attrs.check_allowed({"origin", "target", "up"}, tag, loc);
    auto o = parse_list(attrs.require("origin", tag, loc), 3, loc, "<lookat> origin");
    auto t = parse_list(attrs.require("target", tag, loc), 3, loc, "<lookat> target");
    Vec3 origin{float(o[0]), float(o[1]), float(o[2])};
    Vec3 target{float(t[0]), float(t[1]), float(t[2])};
    Vec3 up;
    if (const std::string* u = attrs.get("up")) {
      auto uv = parse_list(*u, 3, loc, "<lookat> up");
      up = Vec3(float(uv[0]), float(uv[1]), float(uv[2]));
    } else if (length(target - origin) > 0.f) {
      // Mitsuba picks any vector perpendicular to the viewing direction.
      Vec3 d = normalize(target - origin);
      up = std::abs(d.x) > std::abs(d.y) ? Vec3(-d.z, 0.f, d.x) : Vec3(0.f, d.z, -d.y);
    }
    auto xf = Transform::look_at(origin, target, up);
    if (!xf || !(length(up) > 0.f))
      throw SceneError(loc, "<lookat>: origin equals target, or 'up' is zero or parallel to the view direction");
    return xf->matrix();
  }
  throw SceneError(loc, "unexpected " + elem(tag) +
                            " inside <transform> (expected translate, rotate, scale, matrix or lookat)");
}

}  // namespace tessera::xml
