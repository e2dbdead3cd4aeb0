// The SD-tree as bytes, for guiding on the render farm.
//
// A tree: everything a pass samples and records with (the spatial nodes, each leaf's sampling and
// building directional trees, its BSDF fraction), so a worker renders a unit with exactly the tree
// a local render would have at that pass. Training records: what one unit's training added to a
// tree, recorded into a recorder (the tree's cells with zero sums) and written sparsely; the
// coordinator adds every unit's records to its copy of the tree. The sums are integers, so the
// result is the tree a local render builds, in any order of units.
//
// Raw little-endian bytes (the farm compresses them). Reading checks every index, so bytes from
// the network cannot make a tree that traversal would leave or loop in.
#pragma once

#include "tessera/guiding/spatial_tree.h"

#include <string>
#include <string_view>

namespace tessera {

std::string write_tree(const SpatialTree& tree);
/// False with `error` set when the bytes are not a well-formed tree.
[[nodiscard]] bool read_tree(std::string_view bytes, SpatialTree& out, std::string& error);

/// A tree with `tree`'s cells and zero sums, without its sampling distributions: one unit's
/// training goes into it (PathGuide::records).
SpatialTree make_recorder(const SpatialTree& tree);
/// The nonzero sums of a recorder.
std::string write_records(const SpatialTree& recorder);
/// Adds records written from a recorder of a tree with `tree`'s cells. False with `error` set, and
/// `tree` unchanged, when they do not fit it.
[[nodiscard]] bool add_records(SpatialTree& tree, std::string_view records, std::string& error);
/// Whether add_records would take them (nothing changes).
[[nodiscard]] bool check_records(const SpatialTree& tree, std::string_view records, std::string& error);

}  // namespace tessera
