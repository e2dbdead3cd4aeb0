// Which parameters each plugin asks for. While a ParameterLog is alive, every look-up a factory
// makes on a scene node (typed getters, has(), nested objects by name), whether or not the scene
// sets that parameter, is recorded under the node's (tag, type). What a factory asks for is what it
// supports, so docs/plugins.md is checked against this log (tests/scene/plugin_docs_test.cpp).
#pragma once

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <utility>

namespace tessera {

struct SceneNode;

class ParameterLog {
 public:
  using Key = std::pair<std::string, std::string>;  // (tag, plugin type), e.g. ("bsdf", "diffuse")

  /// Starts recording; only one log may be active at a time.
  ParameterLog();
  ~ParameterLog();
  ParameterLog(const ParameterLog&) = delete;
  ParameterLog& operator=(const ParameterLog&) = delete;

  const std::map<Key, std::set<std::string>>& asked() const { return asked_; }

  /// Called by the scene node look-ups; a no-op when no log is active.
  static void record(const SceneNode& node, const std::string& name);

 private:
  std::mutex mutex_;
  std::map<Key, std::set<std::string>> asked_;
};

}  // namespace tessera
