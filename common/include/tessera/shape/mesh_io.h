// Mesh files and analytic meshes -> object-space MeshData.
//
// Every loader validates what it reads and throws SceneError(FileLoc{path, line}, msg) on bad input
// (missing file, truncated data, malformed numbers, NaN/Inf coordinates, out-of-range indices): no
// malformed file can crash the renderer or reach the hot path. Zero-area triangles are not errors
// (real scenes contain them); they are dropped and counted in MeshLoadStats so that the caller can
// emit one warning per file.
//
// Conventions shared by all loaders:
// - normals are per vertex and unit length; a mesh without normals gets smooth vertex normals
//   (angle-weighted, Thuermer & Wuethrich 1998, as Mitsuba computes them), unless `face_normals`
//   is set, in which case `normals` stays empty;
// - `flip_normals` is NOT applied here: TriangleMeshShape negates both normals at render time, so
//   one cached MeshData serves flipped and unflipped instances;
// - uvs are empty when the file has none (the shape then reports barycentrics as uv, as Mitsuba 3).
#pragma once

#include "tessera/render/shape.h"
#include "tessera/scene/error.h"

#include <cstddef>
#include <string>
#include <vector>

namespace tessera {

struct MeshLoadStats {
  size_t degenerate_dropped = 0;  // zero-area triangles removed
};

struct ObjOptions {
  bool face_normals = false;
  bool flip_tex_coords = true;  // Mitsuba 0.6's default for OBJ: v -> 1 - v
};

/// Wavefront OBJ (via tinyobjloader). All groups/objects of the file become one mesh; polygons are
/// fan-triangulated; each distinct (position, uv, normal) index triple becomes one vertex.
MeshData load_obj(const std::string& path, const ObjOptions& options, MeshLoadStats* stats = nullptr);

/// Stanford PLY: ascii, binary_little_endian, binary_big_endian. Reads vertex x,y,z, optional
/// nx,ny,nz and u,v (or s,t / texture_u,texture_v / texture_s,texture_t), and face lists named
/// vertex_indices or vertex_index (polygons fan-triangulated). Other elements/properties are skipped.
MeshData load_ply(const std::string& path, bool face_normals, MeshLoadStats* stats = nullptr);

/// Mitsuba's compressed `.serialized` format (versions 3 and 4), mesh number `shape_index`.
MeshData load_serialized(const std::string& path, int shape_index, bool face_normals,
                         MeshLoadStats* stats = nullptr);
/// Number of meshes in a `.serialized` file (from its end-of-file dictionary).
int serialized_shape_count(const std::string& path);

/// Mitsuba's `rectangle`: [-1,1]^2 at z = 0, normal +z, uv = (p + 1) / 2. Two triangles.
MeshData make_rectangle_mesh();
/// Mitsuba's `cube`: [-1,1]^3, 24 vertices with outward face normals, each face mapped to [0,1]^2.
MeshData make_cube_mesh();
/// Mitsuba's `disk`: unit disk at z = 0, normal +z, as `segments` triangles. The rim radius is
/// enlarged slightly so the polygon's area is exactly pi (an emitting disk keeps its power).
/// uv approximates Mitsuba's polar map (r, phi / 2pi); the seam at phi = 0 has its own vertices.
inline constexpr int kDiskSegments = 128;
MeshData make_disk_mesh(int segments = kDiskSegments);

// -- Helpers shared by the loaders (mesh_util.cpp) --

/// Throws SceneError at `loc` if any position (or normal/uv) is NaN/Inf or any index is out of range.
void validate_mesh(const MeshData& mesh, const FileLoc& loc);
/// Removes zero-area triangles (those whose geometric normal cannot be normalized); returns how many.
size_t drop_degenerate_triangles(MeshData& mesh);
/// Angle-weighted smooth vertex normals. When `only_missing` is non-empty it flags (per vertex) the
/// normals to compute; the others are kept. Vertices no triangle uses get (0, 0, 1).
void compute_smooth_normals(MeshData& mesh, const std::vector<bool>& only_missing = {});
/// Normalizes existing vertex normals; a zero or non-finite normal is recomputed smoothly.
void normalize_vertex_normals(MeshData& mesh);
/// The common tail of every loader: validate, drop degenerates, fix normals per `face_normals`.
void finish_mesh(MeshData& mesh, bool face_normals, const FileLoc& loc, MeshLoadStats* stats);

}  // namespace tessera
