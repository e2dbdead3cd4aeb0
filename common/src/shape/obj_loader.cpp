// Wavefront OBJ -> MeshData, via tinyobjloader.
//
// tinyobjloader is forgiving where we must not be: it reads "nan", "1,5" or a missing coordinate
// as 0, and passes out-of-range indices through. So a light validation pass over the text runs
// first and reports the offending line; tinyobjloader then does the actual parsing, without its own
// triangulation (it splits quads along the shorter diagonal), and this file fan-triangulates
// polygons (0, k, k+1) as Mitsuba does, and merges index triples into vertices.
#include "tessera/shape/mesh_io.h"

#include "tessera/scene/error.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace tessera {

namespace {

constexpr int kMaxPolygon = 255;  // tinyobjloader stores vertex counts per face in a byte

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(FileLoc{path, 0}, "cannot open OBJ file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw SceneError(FileLoc{path, 0}, "error while reading OBJ file");
  return std::move(ss).str();
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Splits a line into whitespace-separated tokens (the line excludes '\n').
void tokenize(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    if (i >= line.size() || line[i] == '#') break;
    size_t j = i;
    while (j < line.size() && !is_space(line[j])) ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
}

enum class Num { Ok, Bad, NonFinite };

Num parse_number(std::string_view tok) {
  if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
  float value = 0.f;
  auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
  if (ec == std::errc::result_out_of_range) return Num::NonFinite;
  if (ec != std::errc() || ptr != tok.data() + tok.size() || tok.empty()) return Num::Bad;
  return std::isfinite(value) ? Num::Ok : Num::NonFinite;
}

/// Parses one index of a face corner ("-3", "12"); false if malformed or zero.
bool parse_index(std::string_view s, long long& out) {
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size() && out != 0;
}

struct Counts {
  long long v = 0, vt = 0, vn = 0;
};

/// Index `idx` (1-based, or negative = relative to `count` so far) must name an existing element.
/// Positive forward references are legal OBJ; they are checked against the final count later.
void check_index(long long idx, long long count, long long& max_forward, const FileLoc& loc,
                 const char* what) {
  if (idx < 0 && count + idx < 0)
    throw SceneError(loc, std::string("relative ") + what + " index " + std::to_string(idx) +
                              " points before the first " + what);
  if (idx > count) max_forward = std::max(max_forward, idx);
}

/// Validates numbers and face indices line by line; returns the number of faces.
size_t validate_obj_text(const std::string& text, const std::string& path) {
  if (std::memchr(text.data(), '\0', text.size()))
    throw SceneError(FileLoc{path, 0}, "not a text file (OBJ expected)");
  Counts counts;
  long long fwd_v = 0, fwd_vt = 0, fwd_vn = 0;
  int fwd_line_v = 0, fwd_line_vt = 0, fwd_line_vn = 0;
  size_t faces = 0;
  std::vector<std::string_view> tok;
  int line_no = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (line.empty()) continue;
    tokenize(line, tok);
    if (tok.empty()) continue;
    FileLoc loc{path, line_no};
    std::string_view kw = tok[0];
    if (kw == "v" || kw == "vn" || kw == "vt") {
      size_t need = kw == "vt" ? 1 : 3;
      if (tok.size() - 1 < need)
        throw SceneError(loc, "'" + std::string(kw) + "' needs " + std::to_string(need) +
                                  " numbers, got " + std::to_string(tok.size() - 1));
      for (size_t k = 1; k < tok.size(); ++k) {
        Num r = parse_number(tok[k]);
        if (r == Num::Bad)
          throw SceneError(loc, "invalid number '" + std::string(tok[k]) + "'");
        // A NaN vertex normal is repairable (it is recomputed); a NaN position or uv is not.
        if (r == Num::NonFinite && kw != "vn")
          throw SceneError(loc, "NaN or infinite coordinate '" + std::string(tok[k]) + "'");
      }
      (kw == "v" ? counts.v : kw == "vt" ? counts.vt : counts.vn)++;
    } else if (kw == "f") {
      size_t n = tok.size() - 1;
      if (n < 3) throw SceneError(loc, "face with fewer than 3 vertices");
      if (n > kMaxPolygon)
        throw SceneError(loc, "polygon with " + std::to_string(n) + " vertices (at most " +
                                  std::to_string(kMaxPolygon) + " supported)");
      for (size_t k = 1; k < tok.size(); ++k) {
        std::string_view t = tok[k];
        size_t s1 = t.find('/');
        size_t s2 = s1 == std::string_view::npos ? s1 : t.find('/', s1 + 1);
        std::string_view sv = t.substr(0, s1), st, sn;
        if (s1 != std::string_view::npos) {
          st = t.substr(s1 + 1, s2 == std::string_view::npos ? std::string_view::npos : s2 - s1 - 1);
          if (s2 != std::string_view::npos) sn = t.substr(s2 + 1);
        }
        long long iv = 0, it = 0, in = 0;
        if (!parse_index(sv, iv) || (!st.empty() && !parse_index(st, it)) ||
            (!sn.empty() && !parse_index(sn, in)) ||
            (s2 != std::string_view::npos && sn.empty()))
          throw SceneError(loc, "malformed face vertex '" + std::string(t) + "'");
        long long before = fwd_v;
        check_index(iv, counts.v, fwd_v, loc, "vertex");
        if (fwd_v != before) fwd_line_v = line_no;
        if (it) {
          before = fwd_vt;
          check_index(it, counts.vt, fwd_vt, loc, "texture coordinate");
          if (fwd_vt != before) fwd_line_vt = line_no;
        }
        if (in) {
          before = fwd_vn;
          check_index(in, counts.vn, fwd_vn, loc, "normal");
          if (fwd_vn != before) fwd_line_vn = line_no;
        }
      }
      ++faces;
    }
  }
  auto forward = [&](long long max_idx, long long count, int line, const char* what) {
    if (max_idx > count)
      throw SceneError(FileLoc{path, line},
                       std::string(what) + " index " + std::to_string(max_idx) +
                           " out of range (the file has " + std::to_string(count) + ")");
  };
  forward(fwd_v, counts.v, fwd_line_v, "vertex");
  forward(fwd_vt, counts.vt, fwd_line_vt, "texture coordinate");
  forward(fwd_vn, counts.vn, fwd_line_vn, "normal");
  return faces;
}

struct CornerKey {
  int vt, vn;
  int v;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  size_t operator()(const CornerKey& k) const {
    uint64_t h = uint64_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull;
    h ^= (uint64_t(uint32_t(k.vt)) << 32 | uint32_t(k.vn)) + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2);
    return size_t(h);
  }
};

}  // namespace

MeshData load_obj(const std::string& path, const ObjOptions& options, MeshLoadStats* stats) {
  const FileLoc file_loc{path, 0};
  std::string text = read_text_file(path);
  size_t faces = validate_obj_text(text, path);
  if (faces == 0) throw SceneError(file_loc, "OBJ file contains no faces");

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  {
    std::istringstream in(std::move(text));
    // No material reader: `mtllib` is ignored (the scene assigns BSDFs); no triangulation (see top).
    bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, nullptr,
                               /*triangulate=*/false, /*default_vcols_fallback=*/false);
    if (!ok) throw SceneError(file_loc, "cannot parse OBJ: " + err);
  }

  const int num_v = int(attrib.vertices.size() / 3);
  const int num_vn = int(attrib.normals.size() / 3);
  const int num_vt = int(attrib.texcoords.size() / 2);

  MeshData mesh;
  std::vector<int> vert_vt, vert_vn;            // per output vertex: its source indices
  std::vector<uint32_t> first(size_t(num_v), UINT32_MAX);  // first output vertex per position
  std::unordered_map<CornerKey, uint32_t, CornerHash> extra;
  bool any_vt = false, any_vn = false;

  auto vertex_for = [&](const tinyobj::index_t& c) -> uint32_t {
    int v = c.vertex_index;
    int vt = c.texcoord_index < num_vt ? c.texcoord_index : -2;
    int vn = options.face_normals ? -1 : (c.normal_index < num_vn ? c.normal_index : -2);
    if (v < 0 || v >= num_v || vt < -1 || vn < -1)
      throw SceneError(file_loc, "face references an element that does not exist");
    uint32_t j = first[size_t(v)];
    if (j != UINT32_MAX) {
      if (vert_vt[j] == vt && vert_vn[j] == vn) return j;
      auto it = extra.find(CornerKey{vt, vn, v});
      if (it != extra.end()) return it->second;
    }
    uint32_t idx = uint32_t(mesh.positions.size());
    const float* p = &attrib.vertices[3 * size_t(v)];
    mesh.positions.push_back(Vec3(p[0], p[1], p[2]));
    vert_vt.push_back(vt);
    vert_vn.push_back(vn);
    any_vt |= vt >= 0;
    any_vn |= vn >= 0;
    if (j == UINT32_MAX)
      first[size_t(v)] = idx;
    else
      extra.emplace(CornerKey{vt, vn, v}, idx);
    return idx;
  };

  for (const tinyobj::shape_t& shape : shapes) {
    const auto& idx = shape.mesh.indices;
    size_t offset = 0;
    for (unsigned char fv : shape.mesh.num_face_vertices) {
      size_t n = fv;
      if (offset + n > idx.size()) throw SceneError(file_loc, "inconsistent face data");
      if (n >= 3) {
        uint32_t v0 = vertex_for(idx[offset]);
        uint32_t prev = vertex_for(idx[offset + 1]);
        for (size_t k = 2; k < n; ++k) {
          uint32_t cur = vertex_for(idx[offset + k]);
          mesh.indices.insert(mesh.indices.end(), {v0, prev, cur});
          prev = cur;
        }
      }
      offset += n;
    }
  }

  const size_t nv = mesh.positions.size();
  if (any_vt) {
    mesh.uvs.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      if (vert_vt[i] < 0) continue;  // no uv on this corner: (0, 0), as Mitsuba
      const float* t = &attrib.texcoords[2 * size_t(vert_vt[i])];
      mesh.uvs[i] = Vec2(t[0], options.flip_tex_coords ? 1.f - t[1] : t[1]);
    }
  }
  if (any_vn) {
    // Corners without a normal get (0,0,0), which finish_mesh recomputes from adjacent faces.
    mesh.normals.assign(nv, Vec3(0.f));
    for (size_t i = 0; i < nv; ++i) {
      if (vert_vn[i] < 0) continue;
      const float* q = &attrib.normals[3 * size_t(vert_vn[i])];
      mesh.normals[i] = Vec3(q[0], q[1], q[2]);
    }
  }
  finish_mesh(mesh, options.face_normals, file_loc, stats);
  return mesh;
}

}  // namespace tessera
