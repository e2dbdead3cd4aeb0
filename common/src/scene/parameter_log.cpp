#include "tessera/scene/parameter_log.h"

#include "tessera/core/check.h"
#include "tessera/scene/scene_desc.h"

#include <atomic>

namespace tessera {
namespace {

// Global rather than thread-local: loaders may call factories from worker threads.
std::atomic<ParameterLog*> g_active{nullptr};

}  // namespace

ParameterLog::ParameterLog() {
  ParameterLog* expected = nullptr;
  TESSERA_CHECK(g_active.compare_exchange_strong(expected, this));
}

ParameterLog::~ParameterLog() { g_active.store(nullptr); }

void ParameterLog::record(const SceneNode& node, const std::string& name) {
  ParameterLog* log = g_active.load(std::memory_order_relaxed);
  if (!log) return;
  std::lock_guard<std::mutex> lock(log->mutex_);
  log->asked_[{node.tag, node.type}].insert(name);
}

}  // namespace tessera
