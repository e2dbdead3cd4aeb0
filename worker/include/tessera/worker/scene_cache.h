// A worker's scenes: bundles downloaded once (verified by hash) into the cache directory, only
// the files a job's scene references unpacked, and loaded scenes (with their BVH) kept across
// tiles and jobs, least recently used evicted beyond a memory budget. Guided jobs' guides
// (guide_artifact.h) and sppm and vcm jobs' point maps (photon_program.h) are downloaded once each
// and kept under the same budget.
#pragma once

#include "tessera/farm/protocol.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/scene.h"
#include "tessera/sequence/artifact.h"
#include "tessera/client/farm_api.h"

#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace tessera::farm {

struct CachedScene {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<const SpatialTree> guide;  // an entry for a guide holds it instead of a scene,
  std::shared_ptr<const Artifact> points;    // or for a point map (sppm's photons, vcm's light vertices)
  uint64_t bytes = 0;  // Scene::memory (BVHs, meshes, images), or the guide's
};

class SceneCache {
 public:
  SceneCache(std::string cache_dir, uint64_t memory_budget);

  /// The loaded scene for a lease; downloads, unpacks and loads on first use. Concurrent callers
  /// for the same scene wait for one load. Throws std::runtime_error (download/bundle problems) or
  /// the loader's SceneError/UnsupportedError.
  std::shared_ptr<const CachedScene> get(const Lease& lease, const client::FarmApi& api);
  /// The artifact a lease renders with (lease.guide set), fetched and checked on first use: a guide,
  /// or the point map of `scene`'s sppm or vcm integrator.
  std::shared_ptr<const CachedScene> guide(const Lease& lease, const client::FarmApi& api, const Scene& scene);

  size_t loaded_scenes() const;
  /// Bytes and number of the scenes and guides loaded now (those still loading not counted).
  WorkerMemory memory() const;
  /// Number of bundle downloads so far (a test checks each bundle is fetched once).
  uint64_t downloads() const { return downloads_; }

 private:
  std::string bundle_file(const Lease& lease, const client::FarmApi& api);
  std::shared_ptr<const CachedScene> load(const Lease& lease, const client::FarmApi& api);
  std::shared_ptr<const CachedScene> cached(const std::string& key,
                                            const std::function<std::shared_ptr<const CachedScene>()>& load);
  void evict_locked();

  std::string dir_;
  uint64_t budget_;
  mutable std::mutex mutex_;
  std::mutex download_mutex_;
  struct Entry {
    std::shared_future<std::shared_ptr<const CachedScene>> scene;
    std::list<std::string>::iterator lru;
  };
  std::map<std::string, Entry> entries_;
  std::list<std::string> lru_;  // most recent first
  std::atomic<uint64_t> downloads_{0};
};

}  // namespace tessera::farm
