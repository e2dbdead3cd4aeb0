// Decoding a scene's bitmaps ahead of the build: collect (file, decoding) pairs from the parsed
// description, decode the distinct ones on all cores, hand them to the load's cache.
#include "tessera/texture/bitmap_prefetch.h"

#include "tessera/texture/bitmap_decode.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <vector>

namespace tessera {

namespace {

struct DecodeJob {
  std::string key, path;
  BitmapDecodeSettings settings;
  uintmax_t file_bytes = 0;
};

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

std::vector<DecodeJob> decode_jobs(const LoadContext& ctx) {
  std::vector<const SceneNode*> nodes;
  std::set<const SceneNode*> seen;
  if (ctx.desc().root) collect_bitmaps(*ctx.desc().root, seen, nodes);
  std::vector<DecodeJob> jobs;
  std::set<std::string> keys;
  for (const SceneNode* node : nodes) {
    const Property* file = node->peek("filename");
    std::optional<BitmapDecodeSettings> settings = quiet_settings(*node);
    if (!file || file->type != PropType::String || !settings) continue;
    DecodeJob job;
    try {
      job.path = ctx.locate_file(file->s, file->loc);
    } catch (const SceneError&) {
      continue;
    }
    job.settings = *settings;
    job.key = bitmap_cache_key(job.path, job.settings);
    if (ctx.has_resource<DecodedBitmap>(job.key) || !keys.insert(job.key).second) continue;
    std::error_code ec;
    job.file_bytes = std::filesystem::file_size(job.path, ec);
    jobs.push_back(std::move(job));
  }
  // Largest files first, so that the last image to finish is a small one.
  std::stable_sort(jobs.begin(), jobs.end(),
                   [](const DecodeJob& a, const DecodeJob& b) { return a.file_bytes > b.file_bytes; });
  return jobs;
}

}  // namespace

void prefetch_bitmaps(LoadContext& ctx) {
  const std::vector<DecodeJob> jobs = decode_jobs(ctx);
  std::vector<std::shared_ptr<const DecodedBitmap>> decoded(jobs.size());
  tbb::parallel_for(size_t(0), jobs.size(), [&](size_t i) {
    try {
      decoded[i] = std::make_shared<const DecodedBitmap>(decode_bitmap_file(jobs[i].path, jobs[i].settings));
    } catch (const std::exception&) {
      // Left for the factory, which decodes it again and reports the error where the scene names it.
    }
  });
  for (size_t i = 0; i < jobs.size(); ++i)
    if (decoded[i]) ctx.add_resource(jobs[i].key, decoded[i]);
}

}  // namespace tessera
