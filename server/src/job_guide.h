// A guided job's SD-tree on the coordinator: the farm's side of render()'s guiding.
//
// Passes 0..m-1 train (guiding_trains_pass), and pass p renders with the tree learned over
// min(p, m) training passes: iteration 0 is the scene's bounds as one leaf. So passes 1..m open
// only at their barrier: once the pass before is complete, its tree plus every tile's training
// records (exact integer sums, guiding/tree_io.h, added in any order) is ended with
// end_iteration(), as render() ends it, and the new tree is stored (encoded off the coordinator's
// lock, under its hash, guide_artifact.h) before a pass that renders with it is leased. Passes
// after m render with the last tree and open with pass m.
//
// Memory: the latest tree, and while a training pass runs a second copy that its records go into
// (each at most GuidingSettings::max_bytes, 256 MB by default; tens of MB on the shared interiors).
#pragma once

#include "tessera/farm/job_scene.h"
#include "tessera/guiding/spatial_tree.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tessera::server {

class JobGuide {
 public:
  JobGuide(const JobPlan::Guide& plan, const std::vector<uint32_t>& passes, uint32_t spp);

  /// The iteration (training passes learned) pass `pass` renders with.
  uint32_t iteration_of(uint32_t pass) const { return std::min(pass, training_passes_); }
  bool trains(uint32_t pass) const { return pass < training_passes_; }
  /// Whether the pass's units render with a guide (they sample from it or train it).
  bool guides(uint32_t pass) const { return trains(pass) || iteration_of(pass) > 0; }
  /// Whether the pass's samples stay out of the image (GuidingSettings::discard_training).
  bool discards(uint32_t pass) const { return trains(pass) && settings_.discard_training; }
  /// Whether the pass opens only once the pass before is complete (its tree is made from it).
  bool at_barrier(uint32_t pass) const { return pass >= 1 && pass <= training_passes_; }

  /// Whether the tree of iteration `i` is made (then also: whether it is stored, and its hash).
  bool made(uint32_t i) const { return made_ >= int64_t(i); }
  bool stored(uint32_t i) const { return i < hashes_.size(); }
  const std::string& hash(uint32_t i) const { return hashes_.at(i); }
  uint32_t stored_count() const { return uint32_t(hashes_.size()); }

  /// Makes the next iteration's tree from the latest one and the records added to it (at the
  /// barrier of the pass after the training pass, which must be complete).
  void end_iteration();
  /// The newest made tree while it is not stored yet, once: to be encoded and stored.
  std::optional<std::pair<uint32_t, std::shared_ptr<const SpatialTree>>> take_tree_to_store();
  /// Iteration `i`'s tree is stored under `hash` (iterations in order).
  void stored_as(uint32_t i, std::string hash);

  /// Whether a result of `pass` carries what it should: records that fit the tree it trained
  /// (checked without changing it), or none for a pass that does not train.
  [[nodiscard]] bool check_records(uint32_t pass, std::string_view records, std::string& error) const;
  /// Adds a checked training result's records.
  void add_records(std::string_view records);

  /// Rebuilding: the stored trees' hashes (in order) and the latest one, decoded.
  void restore(std::vector<std::string> hashes, std::shared_ptr<const SpatialTree> latest);
  size_t tree_bytes() const { return tree_ ? tree_->bytes() : released_bytes_; }
  /// How long the latest end_iteration took (at the barrier, under the coordinator's lock).
  double end_seconds() const { return end_seconds_; }
  size_t tree_leaves() const { return tree_ ? tree_->leaf_count() : released_leaves_; }
  /// Frees the trees of a job that has ended (their sizes stay for its status).
  void release_trees() {
    released_bytes_ = tree_bytes();
    released_leaves_ = tree_leaves();
    tree_.reset();
    training_.reset();
  }

 private:
  GuidingSettings settings_;
  uint32_t training_passes_ = 0;
  int64_t made_ = 0;                           // the latest made iteration
  std::shared_ptr<const SpatialTree> tree_;    // its tree
  std::unique_ptr<SpatialTree> training_;      // that tree plus the records added so far
  bool store_pending_ = false;                 // iteration made_ is not handed out for storing yet
  std::vector<std::string> hashes_;            // per stored iteration
  double end_seconds_ = 0;
  size_t released_bytes_ = 0, released_leaves_ = 0;
};

}  // namespace tessera::server
