#include "tessera/worker/scene_cache.h"

#include "tessera/farm/bundle.h"
#include "tessera/sequence/guide_artifact.h"
#include "tessera/sequence/photon_program.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/mapped_file.h"
#include "tessera/farm/sha256.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

namespace tessera::farm {

namespace fs = std::filesystem;

SceneCache::SceneCache(std::string cache_dir, uint64_t budget) : dir_(std::move(cache_dir)), budget_(budget) {
  fs::create_directories(fs::path(dir_) / "bundles");
  fs::create_directories(fs::path(dir_) / "scenes");
}

std::string SceneCache::bundle_file(const Lease& lease, const client::FarmApi& api) {
  const std::string& hash = lease.settings.scene;
  const fs::path path = fs::path(dir_) / "bundles" / (hash + ".bundle");
  std::lock_guard<std::mutex> lock(download_mutex_);
  if (fs::exists(path)) return path.string();
  // Straight to disk (a bundle may be gigabytes), checked there, then renamed into place.
  const fs::path tmp = path.string() + ".tmp" + std::to_string(std::random_device{}());
  client::HttpReply r = api.download_scene(hash, tmp.string());
  std::error_code ec;
  if (!r.ok()) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot download scene bundle " + hash + ": " + r.describe());
  }
  if (sha256_file_hex(tmp.string()) != hash) {
    fs::remove(tmp, ec);
    throw std::runtime_error("scene bundle " + hash + " arrived corrupt (hash mismatch)");
  }
  fs::rename(tmp, path);
  ++downloads_;
  spdlog::info("downloaded scene bundle {} ({} bytes)", hash.substr(0, 12), fs::file_size(path, ec));
  return path.string();
}

std::shared_ptr<const CachedScene> SceneCache::load(const Lease& lease, const client::FarmApi& api) {
  const std::string bundle = bundle_file(lease, api);
  // Only what the scene references is unpacked; the directory is keyed by that list, so two jobs
  // that use different parts of one bundle do not disturb each other.
  std::string files_key;
  for (const auto& f : lease.files) files_key += f + "\n";
  const fs::path dir = fs::path(dir_) / "scenes" / (lease.settings.scene.substr(0, 32) + "-" + sha256_hex(files_key).substr(0, 16));
  {
    std::lock_guard<std::mutex> lock(download_mutex_);
    if (!fs::exists(dir)) {
      const MappedFile bytes(bundle);
      // The coordinator checked the bundle's compression ratio against its own --max-ratio (which
      // its operator may have raised for a scene): refusing here what it accepted would fail the job.
      BundleLimits limits;
      limits.max_ratio = 0;
      BundleResult r = unpack_bundle(bytes.bytes(), dir.string(), limits,
                                     std::set<std::string>(lease.files.begin(), lease.files.end()));
      if (!r.ok()) throw std::runtime_error("scene bundle " + lease.settings.scene.substr(0, 12) + ": " + r.error);
    }
  }
  LoadedJobScene loaded = load_job_scene(dir.string(), lease.scene_file, lease.settings);
  auto out = std::make_shared<CachedScene>();
  out->scene = std::move(loaded.loaded.scene);
  out->bytes = out->scene->memory().total();
  return out;
}

std::shared_ptr<const CachedScene> SceneCache::get(const Lease& lease, const client::FarmApi& api) {
  return cached(scene_cache_key(lease.settings, lease.scene_file), [&] { return load(lease, api); });
}

std::shared_ptr<const CachedScene> SceneCache::guide(const Lease& lease, const client::FarmApi& api, const Scene& scene) {
  const std::string& hash = lease.guide.value().hash;
  return cached("guide " + hash, [&] {
    client::HttpReply r = api.download_guide(hash);
    if (!r.ok()) throw std::runtime_error("cannot download guide " + hash + ": " + r.describe());
    if (sha256_hex(r.body) != hash) throw std::runtime_error("guide " + hash + " arrived corrupt (hash mismatch)");
    auto out = std::make_shared<CachedScene>();
    std::string error;
    if (uses_light_vertex_passes(scene.integrator.type)) {
      out->points = decode_point_map(scene.integrator.type, r.body, error);
      if (!out->points) throw std::runtime_error("point map " + hash.substr(0, 12) + ": " + error);
      out->bytes = out->points->memory_bytes();
    } else {
      auto tree = std::make_unique<SpatialTree>();
      if (!decode_guide(r.body, *tree, error)) throw std::runtime_error(error);
      out->bytes = tree->bytes();
      out->guide = std::move(tree);
    }
    spdlog::info("downloaded {} {} of job {} ({} bytes, {} MB in memory)", out->points ? "point map" : "guide",
                 hash.substr(0, 12), lease.job_id, r.body.size(), out->bytes >> 20);
    return out;
  });
}

std::shared_ptr<const CachedScene> SceneCache::cached(const std::string& key,
                                                      const std::function<std::shared_ptr<const CachedScene>()>& load) {
  std::promise<std::shared_ptr<const CachedScene>> promise;
  std::shared_future<std::shared_ptr<const CachedScene>> future;
  bool loader = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = entries_.find(key);
    if (it != entries_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second.lru);
      future = it->second.scene;
    } else {
      future = promise.get_future().share();
      lru_.push_front(key);
      entries_[key] = Entry{future, lru_.begin()};
      loader = true;
    }
  }
  if (loader) {
    try {
      promise.set_value(load());
    } catch (...) {
      // A failed load is not cached: the next lease tries again (the bundle may have been fixed).
      promise.set_exception(std::current_exception());
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = entries_.find(key);
      if (it != entries_.end()) {
        lru_.erase(it->second.lru);
        entries_.erase(it);
      }
      throw;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    evict_locked();
  }
  return future.get();
}

void SceneCache::evict_locked() {
  // Oldest first; a scene in use (another reference alive) or still loading stays.
  uint64_t total = 0;
  for (auto& [k, e] : entries_)
    if (e.scene.wait_for(std::chrono::seconds(0)) == std::future_status::ready) total += e.scene.get()->bytes;
  // The most recent entry (the scene just loaded) is never evicted: the caller is about to use it.
  for (auto it = std::prev(lru_.end()); it != lru_.begin() && total > budget_;) {
    auto e = entries_.find(*it);
    if (e->second.scene.wait_for(std::chrono::seconds(0)) != std::future_status::ready ||
        e->second.scene.get().use_count() > 1) {  // loading, or a slot is rendering with it
      --it;
      continue;
    }
    const auto& scene = e->second.scene.get();
    total -= scene->bytes;
    spdlog::info("evicting scene {} ({} MB) from the cache", it->substr(0, 12), scene->bytes >> 20);
    entries_.erase(e);
    it = std::prev(lru_.erase(it));
  }
}

WorkerMemory SceneCache::memory() const {
  std::lock_guard<std::mutex> lock(mutex_);
  WorkerMemory m;
  for (auto& [key, e] : entries_) {
    if (e.scene.wait_for(std::chrono::seconds(0)) != std::future_status::ready) continue;
    try {
      m.scene_bytes += e.scene.get()->bytes;
      ++m.scenes;
    } catch (const std::exception&) {  // a load that failed holds nothing
    }
  }
  return m;
}

size_t SceneCache::loaded_scenes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

}  // namespace tessera::farm
