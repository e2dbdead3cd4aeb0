// Decoding a scene's bitmaps ahead of the build: collect (file, decoding) pairs from the parsed
// description and decode the distinct ones in TBB tasks while the build goes on.
#include "tessera/texture/bitmap_prefetch.h"

#include "tessera/texture/bitmap_decode.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <vector>

namespace tessera {

namespace {

// The resource key the background work is kept under in the LoadContext.
const char* const kPrefetchKey = "bitmap prefetch";

void collect_bitmaps(const SceneNode& node, std::set<const SceneNode*>& seen, std::vector<const SceneNode*>& out) {
  if (!seen.insert(&node).second) return;
  if (node.tag == "texture" && node.type == "bitmap") out.push_back(&node);
  for (const auto& c : node.children) collect_bitmaps(*c, seen, out);
}

// make_bitmap's reading of gamma, raw and channel, without side effects; empty when a value is
// one the factory would refuse (it then reports it).
std::optional<BitmapDecodeSettings> quiet_settings(const SceneNode& node) {
  BitmapDecodeSettings s;
  if (const Property* p = node.peek("gamma")) {
    if (p->type == PropType::Float) s.gamma = float(p->f);
    else if (p->type == PropType::Integer) s.gamma = float(p->i);
    else return std::nullopt;
    if (!(s.gamma == 0.f || s.gamma == -1.f || (s.gamma > 0.f && std::isfinite(s.gamma)))) return std::nullopt;
  }
  if (const Property* p = node.peek("raw")) {
    if (p->type != PropType::Boolean) return std::nullopt;
    s.raw = p->b;
  }
  if (const Property* p = node.peek("channel")) {
    if (p->type != PropType::String) return std::nullopt;
    std::string c = p->s;
    std::transform(c.begin(), c.end(), c.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    if (c.size() > 1 || (c.size() == 1 && std::string("rgba").find(c[0]) == std::string::npos)) return std::nullopt;
    s.channel = c.empty() ? -1 : int(std::string("rgba").find(c[0]));
  }
  return s;
}

std::vector<BitmapDecodeJob> decode_jobs(const LoadContext& ctx) {
  std::vector<const SceneNode*> nodes;
  std::set<const SceneNode*> seen;
  // From what the scene renders (shapes, emitters, ...), not from top-level bsdf and texture
  // definitions: those are reached through the references that use them, and one nothing uses
  // (a wrapper around the bsdf the shapes name, say) is not worth decoding.
  if (ctx.desc().root)
    for (const auto& child : ctx.desc().root->children)
      if (child->tag != "bsdf" && child->tag != "texture") collect_bitmaps(*child, seen, nodes);
  std::vector<std::pair<uintmax_t, BitmapDecodeJob>> sized;
  std::set<std::string> keys;
  for (const SceneNode* node : nodes) {
    const Property* file = node->peek("filename");
    std::optional<BitmapDecodeSettings> settings = quiet_settings(*node);
    if (!file || file->type != PropType::String || !settings) continue;
    BitmapDecodeJob job;
    try {
      job.path = ctx.locate_file(file->s, file->loc);
    } catch (const SceneError&) {
      continue;
    }
    job.settings = *settings;
    job.key = bitmap_cache_key(job.path, job.settings);
    if (!keys.insert(job.key).second) continue;
    std::error_code ec;
    const uintmax_t bytes = std::filesystem::file_size(job.path, ec);
    sized.emplace_back(ec ? 0 : bytes, std::move(job));
  }
  // Largest files first, so that the last image to finish is a small one.
  std::stable_sort(sized.begin(), sized.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<BitmapDecodeJob> jobs;
  for (auto& [bytes, job] : sized) jobs.push_back(std::move(job));
  return jobs;
}

}  // namespace

BitmapPrefetch::BitmapPrefetch(std::vector<BitmapDecodeJob> jobs) {
  for (BitmapDecodeJob& job : jobs) {
    slots_.push_back(std::make_unique<Slot>());
    slots_.back()->job = std::move(job);
    by_key_[slots_.back()->job.key] = slots_.back().get();
  }
  for (auto& slot : slots_) tasks_.run([this, s = slot.get()] { run(*s); });
}

BitmapPrefetch::~BitmapPrefetch() {
  tasks_.cancel();
  tasks_.wait();
}

const std::shared_ptr<const DecodedBitmap>& BitmapPrefetch::run(Slot& slot) const {
  int expected = kPending;
  if (slot.state.compare_exchange_strong(expected, kRunning, std::memory_order_acq_rel)) {
    try {
      slot.result = std::make_shared<const DecodedBitmap>(decode_bitmap_file(slot.job.path, slot.job.settings));
    } catch (...) {
      // Left null: the factory decodes the file again and reports the error with its location.
    }
    slot.state.store(kDone, std::memory_order_release);
    slot.state.notify_all();
  } else {
    for (int s = slot.state.load(std::memory_order_acquire); s != kDone; s = slot.state.load(std::memory_order_acquire))
      slot.state.wait(s, std::memory_order_acquire);
  }
  return slot.result;
}

std::shared_ptr<const DecodedBitmap> BitmapPrefetch::get(const std::string& key) const {
  auto it = by_key_.find(key);
  return it == by_key_.end() ? nullptr : run(*it->second);
}

size_t BitmapPrefetch::wait_all() const {
  size_t decoded = 0;
  for (auto& slot : slots_) decoded += run(*slot) != nullptr;
  return decoded;
}

void prefetch_bitmaps(LoadContext& ctx) {
  try {
    std::vector<BitmapDecodeJob> jobs = decode_jobs(ctx);
    if (jobs.empty()) return;
    ctx.add_resource<BitmapPrefetch>(kPrefetchKey, std::make_shared<BitmapPrefetch>(std::move(jobs)));
  } catch (const std::exception&) {
    // Looking ahead is an optimisation: without it, the factory decodes each file itself.
  }
}

const BitmapPrefetch* bitmap_prefetch(const LoadContext& ctx) {
  return ctx.find_resource<BitmapPrefetch>(kPrefetchKey).get();
}

}  // namespace tessera
