#include "job_guide.h"

#include "tessera/core/check.h"
#include "tessera/guiding/tree_io.h"
#include "tessera/render/renderer.h"

#include <chrono>

namespace tessera::server {

JobGuide::JobGuide(const JobPlan::Guide& plan, const std::vector<uint32_t>& passes, uint32_t spp)
    : settings_(plan.settings), tree_(std::make_shared<const SpatialTree>(plan.bounds, plan.settings.bsdf_fraction)) {
  while (training_passes_ < passes.size() && guiding_trains_pass(passes, training_passes_, spp)) ++training_passes_;
  store_pending_ = training_passes_ > 0;  // (without training no pass guides: render() samples nothing)
}

void JobGuide::end_iteration() {
  TESSERA_CHECK(made_ < int64_t(training_passes_));
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<SpatialTree> next = training_ ? std::move(training_) : std::make_unique<SpatialTree>(*tree_);
  next->end_iteration(int(made_), settings_);
  end_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  tree_ = std::move(next);
  ++made_;
  store_pending_ = true;
}

std::optional<std::pair<uint32_t, std::shared_ptr<const SpatialTree>>> JobGuide::take_tree_to_store() {
  if (!store_pending_ || stored(uint32_t(made_))) return std::nullopt;
  store_pending_ = false;
  return std::pair{uint32_t(made_), tree_};
}

void JobGuide::stored_as(uint32_t i, std::string hash) {
  if (i == hashes_.size()) hashes_.push_back(std::move(hash));
}

bool JobGuide::check_records(uint32_t pass, std::string_view records, std::string& error) const {
  if (!trains(pass)) {
    if (records.empty()) return true;
    error = "training records for a pass that does not train the job's guide";
    return false;
  }
  if (records.empty() || int64_t(pass) != made_) {
    error = "a training pass's result without its training records";
    return false;
  }
  if (!tree_) {
    error = "the job has ended";
    return false;
  }
  return tessera::check_records(*tree_, records, error);
}

void JobGuide::add_records(std::string_view records) {
  if (!training_) training_ = std::make_unique<SpatialTree>(*tree_);
  std::string error;
  TESSERA_CHECK(tessera::add_records(*training_, records, error));  // (checked when the result arrived)
}

void JobGuide::restore(std::vector<std::string> hashes, std::shared_ptr<const SpatialTree> latest) {
  TESSERA_CHECK(!hashes.empty() && latest);
  hashes_ = std::move(hashes);
  made_ = int64_t(hashes_.size()) - 1;
  tree_ = std::move(latest);
  training_.reset();
  store_pending_ = false;
}

}  // namespace tessera::server
