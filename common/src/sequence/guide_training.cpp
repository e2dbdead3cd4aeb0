#include "tessera/sequence/guide_training.h"

#include "tessera/core/check.h"
#include "tessera/guiding/tree_io.h"

#include <chrono>

namespace tessera {

GuideTraining::GuideTraining(const Bounds3& bounds, const GuidingSettings& settings, std::vector<uint32_t> iteration_spp)
    : bounds_(bounds), settings_(settings), iteration_spp_(std::move(iteration_spp)) {}

std::shared_ptr<const Artifact> GuideTraining::build(uint32_t iteration) {
  TESSERA_CHECK(int64_t(iteration) == made_ + 1);
  const auto t0 = std::chrono::steady_clock::now();
  if (iteration == 0) {
    tree_ = std::make_shared<const SpatialTree>(bounds_, settings_.bsdf_fraction);
  } else {
    std::unique_ptr<SpatialTree> next = training_ ? std::move(training_) : std::make_unique<SpatialTree>(*tree_);
    TESSERA_CHECK(iteration <= iteration_spp_.size());
    next->end_iteration(iteration_spp_[iteration - 1], settings_);
    tree_ = std::move(next);
  }
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  made_ = iteration;
  return std::make_shared<const GuideArtifact>(tree_);
}

bool GuideTraining::check_records(uint32_t iteration, std::string_view records, std::string& error) const {
  if (records.empty() || int64_t(iteration) != made_ + 1) {
    error = "a training pass's result without its training records";
    return false;
  }
  if (!tree_) {
    error = "the job has ended";
    return false;
  }
  return tessera::check_records(*tree_, records, error);
}

void GuideTraining::add_records(uint32_t iteration, uint64_t /*unit*/, std::string_view records) {
  TESSERA_CHECK(int64_t(iteration) == made_ + 1);
  std::string error;
  TESSERA_CHECK(tessera::add_records(recorder(), records, error));  // (checked when the result arrived)
}

SpatialTree& GuideTraining::recorder() {
  TESSERA_CHECK(tree_ != nullptr);
  if (!training_) training_ = std::make_unique<SpatialTree>(*tree_);
  return *training_;
}

std::shared_ptr<const Artifact> GuideTraining::decode(std::string_view bytes, std::string& error) const {
  auto tree = std::make_shared<SpatialTree>();
  if (!decode_guide(bytes, *tree, error)) return nullptr;
  return std::make_shared<const GuideArtifact>(std::move(tree));
}

void GuideTraining::restore(uint32_t iteration, std::shared_ptr<const Artifact> artifact) {
  const auto* guide = dynamic_cast<const GuideArtifact*>(artifact.get());
  TESSERA_CHECK(guide != nullptr);
  tree_ = guide->shared_tree();
  training_.reset();
  made_ = iteration;
}

void GuideTraining::release() {
  released_bytes_ = tree_bytes();
  released_leaves_ = tree_leaves();
  released_gain_ = predicted_gain();
  released_aside_ = stepped_aside();
  tree_.reset();
  training_.reset();
}

}  // namespace tessera
