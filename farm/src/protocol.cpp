#include "tessera/farm/protocol.h"

#include "json_fields.h"
#include "tessera/farm/sha256.h"

#include <openssl/evp.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace tessera {

using nlohmann::json;
using json_fields::Fields;

namespace {

size_t base64_size(size_t bytes) { return 4 * ((bytes + 2) / 3); }

std::string to_base64(std::string_view bytes) {
  std::string out(base64_size(bytes.size()), '\0');
  const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()),
                                reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()));
  out.resize(size_t(std::max(n, 0)));
  return out;
}

bool from_base64(std::string_view text, std::string& out) {
  if (text.size() % 4 != 0) return false;
  out.assign(text.size() / 4 * 3, '\0');
  const int n = EVP_DecodeBlock(reinterpret_cast<unsigned char*>(out.data()),
                                reinterpret_cast<const unsigned char*>(text.data()), int(text.size()));
  if (n < 0) return false;
  // (EVP_DecodeBlock keeps the padding's zero bytes.)
  const size_t pad = text.empty() ? 0 : size_t(text.back() == '=') + size_t(text.size() > 1 && text[text.size() - 2] == '=');
  out.resize(size_t(n) - pad);
  return true;
}

// A lease's fields split in two: its own, and its job's (the same in every lease of the job).
json lease_own_json(const Lease& l) {
  json j = {{"id", l.id},
            {"job", l.job_id},
            {"tile", l.tile},
            {"pass", l.pass},
            {"rect", {l.rect.x0, l.rect.y0, l.rect.x1, l.rect.y1}},
            {"sample_begin", l.sample_begin},
            {"sample_end", l.sample_end},
            {"seconds_to_expiry", l.seconds_to_expiry}};
  if (!l.samples.count.empty()) {
    j["first"] = l.samples.first;
    j["count"] = l.samples.count;
  }
  if (l.guide) j["guide"] = {{"hash", l.guide->hash}, {"iteration", l.guide->iteration}, {"train", l.guide->train}};
  if (l.paths) j["paths"] = {l.paths->first, l.paths->second};
  return j;
}

// Its own fields with the tile state (base64 of up to megabytes: left out where only sizes count).
json lease_own_json_with_state(const Lease& l) {
  json j = lease_own_json(l);
  if (!l.tile_state.empty()) j["tile_state"] = to_base64(l.tile_state);
  return j;
}

// An adaptive lease's per-pixel samples: both arrays, one entry per pixel of the rectangle.
bool lease_samples_valid(const Lease& l, std::string& error) {
  const size_t n = size_t(l.rect.area());
  if (l.samples.first.empty() && l.samples.count.empty()) return true;
  if (l.samples.first.size() != n || l.samples.count.size() != n) {
    error = "lease: 'first' and 'count' must have one entry per pixel of 'rect' (" + std::to_string(n) + ")";
    return false;
  }
  for (size_t i = 0; i < n; ++i)
    if (l.samples.count[i] > (1u << 16) || l.samples.first[i] > UINT32_MAX - l.samples.count[i]) {
      error = "lease: pixel " + std::to_string(i) + " has an implausible sample range";
      return false;
    }
  return true;
}

json lease_job_json(const Lease& l) {
  return {{"settings", to_json(l.settings)}, {"scene_file", l.scene_file}, {"files", l.files}};
}

}  // namespace

json to_json(const Lease& l) {
  json j = lease_own_json_with_state(l);
  j.update(lease_job_json(l));
  return j;
}

size_t lease_job_part_bytes(const Lease& l) { return lease_job_json(l).dump().size(); }

size_t lease_json_bytes(const Lease& l, size_t job_part_bytes) {
  // "{own}" and "{job}" make "{own,job}": one byte fewer than the two apart (the order of the
  // keys does not change the length).
  const size_t state = l.tile_state.empty() ? 0 : std::string_view(R"(,"tile_state":"")").size() + base64_size(l.tile_state.size());
  return lease_own_json(l).dump().size() + state + job_part_bytes - 1;
}

bool lease_from_json(const json& j, Lease& out, std::string& error) {
  Fields f(j, error, "lease");
  std::vector<int> rect;
  json settings;
  f.get("id", out.id, true);
  f.get("job", out.job_id, true);
  f.get("tile", out.tile, true);
  f.get("pass", out.pass, true);
  f.get("rect", rect, true);
  f.get("sample_begin", out.sample_begin, true);
  f.get("sample_end", out.sample_end, true);
  f.get("first", out.samples.first);
  f.get("count", out.samples.count);
  f.get("seconds_to_expiry", out.seconds_to_expiry);
  json guide;
  f.get("guide", guide);
  std::string state;
  f.get("tile_state", state);
  std::vector<uint64_t> paths;
  f.get("paths", paths);
  f.get("settings", settings, true);
  f.get("scene_file", out.scene_file, true);
  f.get_list("files", out.files);
  f.finish();
  if (!f.ok()) return false;
  if (rect.size() != 4) {
    error = "lease: 'rect' must be [x0, y0, x1, y1]";
    return false;
  }
  out.rect = {rect[0], rect[1], rect[2], rect[3]};
  // (A photon pass's lease of paths names its pass by sample_begin and has no samples.)
  if (out.rect.empty() || out.sample_end < out.sample_begin || (out.sample_end == out.sample_begin && paths.empty())) {
    error = "lease: empty rectangle or sample range";
    return false;
  }
  out.tile_state.clear();
  if (state.size() > base64_size(kMaxLeaseStateBytes) || !from_base64(state, out.tile_state) || (!state.empty() && !paths.empty())) {
    error = "lease: 'tile_state' must be base64 of at most " + std::to_string(kMaxLeaseStateBytes) + " bytes, on a lease of a tile";
    return false;
  }
  out.samples.rect = out.rect;
  if (!lease_samples_valid(out, error)) return false;
  out.paths.reset();
  if (!paths.empty()) {
    if (paths.size() != 2 || paths[1] <= paths[0] || !out.samples.count.empty()) {
      error = "lease: 'paths' must be [begin, end] with begin < end, on a lease without per-pixel samples";
      return false;
    }
    out.paths = std::pair{paths[0], paths[1]};
  }
  out.guide.reset();
  if (!guide.is_null()) {
    Lease::Guide g;
    Fields h(guide, error, "lease guide");
    h.get("hash", g.hash, true);
    h.get("iteration", g.iteration, true);
    h.get("train", g.train, true);
    h.finish();
    if (!h.ok()) return false;
    if (!is_sha256_hex(g.hash)) {
      error = "lease guide: 'hash' must be a SHA-256 (64 lowercase hex digits)";
      return false;
    }
    out.guide = g;
  }
  return job_settings_from_json(settings, out.settings, error);
}

json to_json(const Registration& r) {
  return {{"id", r.id}, {"lease_timeout", r.lease_timeout}, {"heartbeat_seconds", r.heartbeat_seconds},
          {"max_poll_wait", r.max_poll_wait}};
}

json to_json(const ResultAck& a) {
  json j = {{"accepted", a.accepted}, {"duplicate", a.duplicate}};
  if (a.next_asked) j["lease"] = a.next ? to_json(*a.next) : json(nullptr);
  return j;
}

json to_json(const WorkerHello& h) {
  return {{"name", h.name},       {"threads", h.threads}, {"memory_bytes", h.memory_bytes},
          {"version", h.version}, {"isa", h.isa},         {"probe", h.probe}};
}

bool worker_hello_from_json(const json& j, WorkerHello& out, std::string& error) {
  Fields f(j, error, "worker registration");
  f.get("name", out.name);
  f.get("threads", out.threads);
  f.get("memory_bytes", out.memory_bytes);
  f.get("version", out.version, true);
  f.get("isa", out.isa, true);
  f.get("probe", out.probe, true);
  f.finish();
  if (!f.ok()) return false;
  if (out.threads < 1 || out.threads > 4096) {
    error = "worker registration: 'threads' must be 1..4096";
    return false;
  }
  if (out.name.size() > 200) {
    error = "worker registration: 'name' is longer than 200 characters";
    return false;
  }
  return true;
}

json heartbeat_to_json(const Heartbeat& h) {
  json leases = json::array();
  for (const HeldLease& l : h.leases) leases.push_back({{"id", l.id}, {"job", l.job}, {"tile", l.tile}, {"pass", l.pass}});
  json j{{"leases", leases}};
  if (h.memory) j["memory"] = {{"scene_bytes", h.memory->scene_bytes}, {"scenes", h.memory->scenes}};
  return j;
}

bool heartbeat_from_json(const json& j, Heartbeat& heartbeat, std::string& error) {
  Fields f(j, error, "heartbeat");
  json leases = json::array(), memory;
  f.get("leases", leases);
  f.get("memory", memory);
  f.finish();
  if (!f.ok()) return false;
  heartbeat.memory.reset();
  if (!memory.is_null()) {
    WorkerMemory m;
    Fields g(memory, error, "heartbeat memory");
    g.get("scene_bytes", m.scene_bytes, true);
    g.get("scenes", m.scenes, true);
    g.finish();
    if (!g.ok()) return false;
    heartbeat.memory = m;
  }
  std::vector<HeldLease>& out = heartbeat.leases;
  if (!leases.is_array() || leases.size() > kMaxHeldLeases) {
    error = "heartbeat: 'leases' must be an array of at most " + std::to_string(kMaxHeldLeases) + " leases";
    return false;
  }
  out.clear();
  for (const json& item : leases) {
    HeldLease l;
    Fields g(item, error, "heartbeat lease");
    g.get("id", l.id, true);
    g.get("job", l.job, true);
    g.get("tile", l.tile, true);
    g.get("pass", l.pass, true);
    g.finish();
    if (!g.ok()) return false;
    out.push_back(l);
  }
  return true;
}

std::string resolve_token(const std::string& flag, const std::string& file, const char* env_var) {
  if (!flag.empty()) return flag;
  if (!file.empty()) {
    std::ifstream in(file);
    std::string line;
    if (!in || !std::getline(in, line)) throw std::runtime_error("cannot read a token from '" + file + "'");
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) throw std::runtime_error("the token file '" + file + "' is empty");
    return line;
  }
  const char* env = std::getenv(env_var);
  return env ? env : "";
}

std::string scene_cache_key(const JobSettings& s, const std::string& scene_file) {
  json j = {{"scene", s.scene}, {"file", scene_file},         {"defines", s.defines},
            {"spp", s.spp},     {"width", s.width},           {"height", s.height},
            {"integrator", s.integrator}, {"light_selection", s.light_selection}};
  if (s.allow_unsupported) j["allow_unsupported"] = true;  // (loads differently; absent keeps older keys)
  return sha256_hex(j.dump());
}

}  // namespace tessera
