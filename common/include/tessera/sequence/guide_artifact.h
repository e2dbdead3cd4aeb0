// A guide's learned SD-tree as an artifact (artifact.h): what the passes after a training pass
// render with. Its bytes are the tree (guiding/tree_io.h) as one zstd frame.
#pragma once

#include "tessera/guiding/spatial_tree.h"
#include "tessera/sequence/artifact.h"

#include <memory>
#include <string>
#include <string_view>

namespace tessera {

/// The tree's bytes (write_tree, zstd-compressed).
std::string encode_guide(const SpatialTree& tree);
/// False with `error` set on anything malformed, or a tree above `max_bytes` uncompressed.
[[nodiscard]] bool decode_guide(std::string_view bytes, SpatialTree& out, std::string& error,
                                size_t max_bytes = size_t(1) << 30);

class GuideArtifact final : public Artifact {
 public:
  explicit GuideArtifact(std::shared_ptr<const SpatialTree> tree) : tree_(std::move(tree)) {}
  std::string encode() const override { return encode_guide(*tree_); }
  size_t memory_bytes() const override { return tree_->bytes(); }
  std::optional<uint32_t> stepped_aside_from() const override {
    return tree_->stepped_aside() ? std::optional(tree_->aside_from()) : std::nullopt;
  }
  const SpatialTree& tree() const { return *tree_; }
  const std::shared_ptr<const SpatialTree>& shared_tree() const { return tree_; }

 private:
  std::shared_ptr<const SpatialTree> tree_;
};

}  // namespace tessera
