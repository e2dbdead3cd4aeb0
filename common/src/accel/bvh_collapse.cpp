// Binary SAH tree -> kBvhWidth-wide tree (bvh_binary.h). Opening the child of largest surface area first
// keeps the children a ray is most likely to enter together in one node test (Wald et al., "Getting
// Rid of Packets", 2008; Embree's BVH4 and BVH8 are built the same way). An opened child is replaced in place
// by its two children, so the leaves stay in the binary tree's depth-first order and a leaf's
// packets are contiguous with its neighbours'.
#include "accel/bvh_binary.h"
#include "tessera/core/check.h"

namespace tessera::accel_detail {
namespace {

class Collapser {
 public:
  Collapser(const HugeVector<BinaryNode>& binary, const std::vector<uint32_t>& leaf_refs,
            NodeArray& out)
      : binary_(binary), leaf_refs_(leaf_refs), out_(out) {}

  /// Emits the wide node for binary interior node `b` (and its subtree); returns its index.
  uint32_t emit(uint32_t b) {
    constexpr int W = BvhNode::kWidth;
    uint32_t kids[W] = {b + 1, binary_[b].second};
    int n = 2;
    while (n < W) {
      int open = -1;
      float best = -1.f;
      for (int i = 0; i < n; ++i) {
        const BinaryNode& c = binary_[kids[i]];
        if (c.count > 0) continue;
        const float area = c.bounds.surface_area();
        if (area > best) best = area, open = i;
      }
      if (open < 0) break;
      const uint32_t c = kids[open];
      for (int i = n; i > open + 1; --i) kids[i] = kids[i - 1];
      kids[open] = c + 1;
      kids[open + 1] = binary_[c].second;
      ++n;
    }
    const uint32_t index = uint32_t(out_.size());
    out_.push_back(empty_node());
    for (int i = 0; i < n; ++i) {
      const BinaryNode& c = binary_[kids[i]];
      set_box(index, i, c.bounds);
      const uint32_t ref = c.count > 0 ? leaf_refs_[kids[i]] : emit(kids[i]);
      out_[index].child[i] = ref;  // out_ may have grown: index, not a reference
    }
    return index;
  }

  void emit_leaf_root() {
    out_.push_back(empty_node());
    set_box(0, 0, binary_[0].bounds);
    out_[0].child[0] = leaf_refs_[0];
  }

 private:
  static BvhNode empty_node() {
    BvhNode node{};
    for (int slot = 0; slot < BvhNode::kWidth; ++slot) {
      for (int axis = 0; axis < 3; ++axis) {
        node.bounds[2 * axis][slot] = kInfinity;
        node.bounds[2 * axis + 1][slot] = -kInfinity;
      }
      node.child[slot] = bvh_ref::kEmpty;
    }
    return node;
  }

  void set_box(uint32_t node, int slot, const Bounds3& b) {
    for (int axis = 0; axis < 3; ++axis) {
      out_[node].bounds[2 * axis][slot] = b.lo[axis];
      out_[node].bounds[2 * axis + 1][slot] = b.hi[axis];
    }
  }

  const HugeVector<BinaryNode>& binary_;
  const std::vector<uint32_t>& leaf_refs_;
  NodeArray& out_;
};

}  // namespace

NodeArray collapse_to_wide(const HugeVector<BinaryNode>& binary,
                                       const std::vector<uint32_t>& leaf_refs) {
  NodeArray out;
  if (binary.empty()) return out;
  out.reserve(binary.size() / 3 + 1);
  Collapser collapser(binary, leaf_refs, out);
  if (binary[0].count > 0)
    collapser.emit_leaf_root();
  else
    collapser.emit(0);
  return out;
}

}  // namespace tessera::accel_detail
