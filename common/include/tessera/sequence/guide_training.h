// Path guiding's training as a sequence of artifacts (artifact.h): iteration 0 is the scene's
// bounds as one leaf; iteration i is iteration i-1 ended (SpatialTree::end_iteration) after the
// training records of pass i-1 went into a copy of it. Records are exact integer sums (tree_io.h),
// so the tree is the same bits for any order of units, in one process or across a farm.
//
// A local render's units record into recorder() directly; a farm worker's into a recorder of the
// tree it renders with, whose nonzero sums travel with its result and are added here.
//
// Memory: the latest tree, and while a training pass runs a copy its records go into (each at most
// GuidingSettings::max_bytes, 256 MB by default; tens of MB on the shared interiors).
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/sequence/artifact.h"
#include "tessera/sequence/guide_artifact.h"

#include <memory>
#include <string>
#include <vector>

namespace tessera {

class GuideTraining final : public ArtifactBuilder {
 public:
  /// `iteration_spp[i]`: the samples per pixel of training iteration i, whose records make
  /// artifact i + 1 (they set its spatial split threshold).
  GuideTraining(const Bounds3& bounds, const GuidingSettings& settings, std::vector<uint32_t> iteration_spp);

  std::shared_ptr<const Artifact> build(uint32_t iteration) override;
  [[nodiscard]] bool check_records(uint32_t iteration, std::string_view records, std::string& error) const override;
  void add_records(uint32_t iteration, uint64_t unit, std::string_view records) override;
  std::shared_ptr<const Artifact> decode(std::string_view bytes, std::string& error) const override;
  void restore(uint32_t iteration, std::shared_ptr<const Artifact> artifact) override;
  void release() override;

  /// Where a local render's training units record (a copy of the latest tree, made on first use).
  SpatialTree& recorder();
  const GuidingSettings& settings() const { return settings_; }
  /// The latest tree (null before the first is built, and once released).
  const SpatialTree* latest() const { return tree_.get(); }
  /// How long the latest build took (at a barrier).
  double build_seconds() const { return build_seconds_; }
  /// The latest tree's size; kept once released (a finished job's status).
  size_t tree_bytes() const { return tree_ ? tree_->bytes() : released_bytes_; }
  size_t tree_leaves() const { return tree_ ? tree_->leaf_count() : released_leaves_; }
  /// The gain the deciding iteration predicted (0 before it) and whether guiding stepped aside
  /// (SpatialTree); kept once released.
  float predicted_gain() const { return tree_ ? tree_->predicted_gain() : released_gain_; }
  bool stepped_aside() const { return tree_ ? tree_->stepped_aside() : released_aside_; }

 private:
  Bounds3 bounds_;
  GuidingSettings settings_;
  std::vector<uint32_t> iteration_spp_;
  int64_t made_ = -1;                          // the latest built iteration
  std::shared_ptr<const SpatialTree> tree_;    // its tree
  std::unique_ptr<SpatialTree> training_;      // that tree plus the records added so far
  double build_seconds_ = 0;
  size_t released_bytes_ = 0, released_leaves_ = 0;
  float released_gain_ = 0.f;
  bool released_aside_ = false;
};

}  // namespace tessera
