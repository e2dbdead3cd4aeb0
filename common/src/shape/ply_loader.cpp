// Stanford PLY -> MeshData (ascii, binary_little_endian, binary_big_endian).
//
// The whole file is read into memory and every read is bounds-checked, so a truncated or lying
// header ends in a SceneError, never in an out-of-bounds read or a huge allocation: element counts
// are checked against the bytes that remain before anything is reserved.
#include "tessera/shape/mesh_io.h"

#include "tessera/scene/error.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

namespace tessera {

namespace {

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

bool parse_type(std::string_view s, PlyType& t) {
  static const struct { const char* name; PlyType type; } kTypes[] = {
      {"char", PlyType::I8},    {"int8", PlyType::I8},     {"uchar", PlyType::U8},
      {"uint8", PlyType::U8},   {"short", PlyType::I16},   {"int16", PlyType::I16},
      {"ushort", PlyType::U16}, {"uint16", PlyType::U16},  {"int", PlyType::I32},
      {"int32", PlyType::I32},  {"uint", PlyType::U32},    {"uint32", PlyType::U32},
      {"float", PlyType::F32},  {"float32", PlyType::F32}, {"double", PlyType::F64},
      {"float64", PlyType::F64}};
  for (const auto& e : kTypes)
    if (s == e.name) {
      t = e.type;
      return true;
    }
  return false;
}

size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::I8: case PlyType::U8: return 1;
    case PlyType::I16: case PlyType::U16: return 2;
    case PlyType::I32: case PlyType::U32: case PlyType::F32: return 4;
    case PlyType::F64: return 8;
  }
  return 1;
}

bool is_float(PlyType t) { return t == PlyType::F32 || t == PlyType::F64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32;
  bool is_list = false;
  PlyType count_type = PlyType::U8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> props;
};

enum class Format { Ascii, BinaryLE, BinaryBE };

/// Sequential reader over the body of the file, for either encoding.
class BodyReader {
 public:
  BodyReader(const std::string& data, size_t pos, Format fmt, const std::string& path, int line)
      : data_(data), pos_(pos), fmt_(fmt), path_(path), line_(line) {}

  double read(PlyType t) { return fmt_ == Format::Ascii ? read_ascii(t) : read_binary(t); }
  size_t remaining() const { return data_.size() - pos_; }
  FileLoc loc() const { return FileLoc{path_, fmt_ == Format::Ascii ? line_ : 0}; }
  [[noreturn]] void fail(const std::string& msg) const { throw SceneError(loc(), msg); }

 private:
  double read_binary(PlyType t) {
    size_t n = type_size(t);
    if (remaining() < n) fail("unexpected end of file (truncated PLY data)");
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    bool swap = (fmt_ == Format::BinaryBE) != (std::endian::native == std::endian::big);
    if (swap)
      for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    switch (t) {
      case PlyType::I8: { int8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::U8: return b[0];
      case PlyType::I16: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::U16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::I32: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::U32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::F32: { float v; std::memcpy(&v, b, 4); return v; }
      case PlyType::F64: { double v; std::memcpy(&v, b, 8); return v; }
    }
    return 0;
  }

  double read_ascii(PlyType t) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) {
      if (data_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= data_.size()) fail("unexpected end of file (truncated PLY data)");
    size_t start = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    const char* b = data_.data() + start;
    const char* e = data_.data() + pos_;
    if (*b == '+') ++b;
    if (is_float(t)) {
      double v = 0;
      auto [p, ec] = std::from_chars(b, e, v);
      if (ec == std::errc::result_out_of_range) return HUGE_VAL;  // caught as non-finite
      if (ec != std::errc() || p != e) fail("invalid number '" + token(start) + "'");
      return v;
    }
    long long v = 0;
    auto [p, ec] = std::from_chars(b, e, v);
    if (ec != std::errc() || p != e) fail("invalid integer '" + token(start) + "'");
    return double(v);
  }

  std::string token(size_t start) const { return data_.substr(start, std::min<size_t>(pos_ - start, 40)); }

  const std::string& data_;
  size_t pos_;
  Format fmt_;
  const std::string& path_;
  int line_;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(FileLoc{path, 0}, "cannot open PLY file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw SceneError(FileLoc{path, 0}, "error while reading PLY file");
  return std::move(ss).str();
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

int find_prop(const PlyElement& el, std::initializer_list<const char*> names) {
  for (const char* n : names)
    for (size_t i = 0; i < el.props.size(); ++i)
      if (!el.props[i].is_list && el.props[i].name == n) return int(i);
  return -1;
}

}  // namespace

MeshData load_ply(const std::string& path, bool face_normals, MeshLoadStats* stats) {
  const std::string data = read_file(path);
  const FileLoc file_loc{path, 0};

  // -- Header --
  size_t pos = 0;
  int line_no = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= data.size()) return false;
    size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    line = std::string_view(data.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    return true;
  };
  std::string_view line;
  if (!next_line(line) || split(line) != std::vector<std::string_view>{"ply"})
    throw SceneError(FileLoc{path, 1}, "not a PLY file (missing 'ply' magic)");
  Format fmt = Format::Ascii;
  bool have_format = false, have_end = false;
  std::vector<PlyElement> elements;
  while (next_line(line)) {
    auto tok = split(line);
    FileLoc loc{path, line_no};
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") {
      have_end = true;
      break;
    }
    if (tok[0] == "format") {
      if (tok.size() < 2) throw SceneError(loc, "malformed 'format' line");
      if (tok[1] == "ascii") fmt = Format::Ascii;
      else if (tok[1] == "binary_little_endian") fmt = Format::BinaryLE;
      else if (tok[1] == "binary_big_endian") fmt = Format::BinaryBE;
      else throw SceneError(loc, "unknown PLY format '" + std::string(tok[1]) + "'");
      have_format = true;
    } else if (tok[0] == "element") {
      if (tok.size() != 3) throw SceneError(loc, "malformed 'element' line");
      PlyElement el;
      el.name = tok[1];
      auto [p, ec] = std::from_chars(tok[2].data(), tok[2].data() + tok[2].size(), el.count);
      if (ec != std::errc() || p != tok[2].data() + tok[2].size())
        throw SceneError(loc, "invalid element count '" + std::string(tok[2]) + "'");
      elements.push_back(std::move(el));
    } else if (tok[0] == "property") {
      if (elements.empty()) throw SceneError(loc, "'property' before any 'element'");
      PlyProperty prop;
      bool ok;
      if (tok.size() == 5 && tok[1] == "list") {
        prop.is_list = true;
        ok = parse_type(tok[2], prop.count_type) && parse_type(tok[3], prop.type) &&
             !is_float(prop.count_type);
        prop.name = tok[4];
      } else {
        ok = tok.size() == 3 && parse_type(tok[1], prop.type);
        if (ok) prop.name = tok[2];
      }
      if (!ok) throw SceneError(loc, "malformed 'property' line");
      elements.back().props.push_back(std::move(prop));
    } else {
      throw SceneError(loc, "unknown header keyword '" + std::string(tok[0]) + "'");
    }
  }
  if (!have_format || !have_end) throw SceneError(file_loc, "incomplete PLY header");

  // -- Body --
  BodyReader rd(data, pos, fmt, path, line_no + 1);
  MeshData mesh;
  uint64_t vertex_count = 0;
  for (const auto& el : elements)
    if (el.name == "vertex") vertex_count = el.count;
  if (vertex_count > 0xFFFFFFFFull) throw SceneError(file_loc, "too many vertices");
  bool faces_seen = false;

  for (const PlyElement& el : elements) {
    // Smallest possible encoding of one element: rejects lying counts before any allocation.
    size_t min_bytes = 0;
    for (const auto& p : el.props)
      min_bytes += fmt == Format::Ascii ? 2 : type_size(p.is_list ? p.count_type : p.type);
    if (min_bytes > 0 && el.count > (rd.remaining() + 1) / min_bytes)
      rd.fail("file too short for " + std::to_string(el.count) + " '" + el.name + "' elements");

    if (el.name == "vertex") {
      int ix = find_prop(el, {"x"}), iy = find_prop(el, {"y"}), iz = find_prop(el, {"z"});
      if (ix < 0 || iy < 0 || iz < 0) throw SceneError(file_loc, "vertex element lacks x, y or z");
      int inx = find_prop(el, {"nx"}), iny = find_prop(el, {"ny"}), inz = find_prop(el, {"nz"});
      int iu = find_prop(el, {"u", "s", "texture_u", "texture_s"});
      int iv = find_prop(el, {"v", "t", "texture_v", "texture_t"});
      bool has_n = inx >= 0 && iny >= 0 && inz >= 0, has_uv = iu >= 0 && iv >= 0;
      mesh.positions.resize(el.count);
      if (has_n) mesh.normals.resize(el.count);
      if (has_uv) mesh.uvs.resize(el.count);
      std::vector<double> vals(el.props.size());
      for (uint64_t i = 0; i < el.count; ++i) {
        for (size_t k = 0; k < el.props.size(); ++k) {
          const PlyProperty& p = el.props[k];
          if (p.is_list) {
            double n = rd.read(p.count_type);
            if (n < 0) rd.fail("negative list length");
            for (uint64_t j = 0; j < uint64_t(n); ++j) rd.read(p.type);
          } else {
            vals[k] = rd.read(p.type);
          }
        }
        Vec3 pos3(float(vals[size_t(ix)]), float(vals[size_t(iy)]), float(vals[size_t(iz)]));
        if (!is_finite(pos3))
          rd.fail("vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
        mesh.positions[i] = pos3;
        if (has_n)
          mesh.normals[i] =
              Vec3(float(vals[size_t(inx)]), float(vals[size_t(iny)]), float(vals[size_t(inz)]));
        if (has_uv) mesh.uvs[i] = Vec2(float(vals[size_t(iu)]), float(vals[size_t(iv)]));
      }
    } else if (el.name == "face") {
      faces_seen = true;
      int il = -1;
      for (size_t k = 0; k < el.props.size(); ++k) {
        const std::string& name = el.props[k].name;
        if (el.props[k].is_list && (name == "vertex_indices" || name == "vertex_index")) il = int(k);
      }
      if (il < 0) throw SceneError(file_loc, "face element lacks a vertex_indices list");
      mesh.indices.reserve(size_t(el.count) * 3);
      std::vector<uint32_t> poly;
      for (uint64_t i = 0; i < el.count; ++i) {
        for (size_t k = 0; k < el.props.size(); ++k) {
          const PlyProperty& p = el.props[k];
          if (!p.is_list) {
            rd.read(p.type);
            continue;
          }
          double n = rd.read(p.count_type);
          if (n < 0) rd.fail("negative list length");
          if (int(k) != il) {
            for (uint64_t j = 0; j < uint64_t(n); ++j) rd.read(p.type);
            continue;
          }
          if (n < 3) rd.fail("face " + std::to_string(i) + " has fewer than 3 vertices");
          if (n > double(rd.remaining())) rd.fail("unexpected end of file (truncated PLY data)");
          poly.clear();
          for (uint64_t j = 0; j < uint64_t(n); ++j) {
            double idx = rd.read(p.type);
            if (!(idx >= 0 && idx < double(vertex_count)) || idx != std::floor(idx))
              rd.fail("face " + std::to_string(i) + " references vertex " + std::to_string(idx) +
                      ", but the file has " + std::to_string(vertex_count) + " vertices");
            poly.push_back(uint32_t(idx));
          }
          for (size_t j = 2; j < poly.size(); ++j)
            mesh.indices.insert(mesh.indices.end(), {poly[0], poly[j - 1], poly[j]});
        }
      }
    } else if (!el.props.empty()) {
      for (uint64_t i = 0; i < el.count; ++i)
        for (const PlyProperty& p : el.props) {
          if (!p.is_list) {
            rd.read(p.type);
            continue;
          }
          double n = rd.read(p.count_type);
          if (n < 0) rd.fail("negative list length");
          if (n > double(rd.remaining())) rd.fail("unexpected end of file (truncated PLY data)");
          for (uint64_t j = 0; j < uint64_t(n); ++j) rd.read(p.type);
        }
    }
  }
  if (!faces_seen || mesh.indices.empty()) throw SceneError(file_loc, "PLY file contains no faces");
  finish_mesh(mesh, face_normals, file_loc, stats);
  return mesh;
}

}  // namespace tessera
