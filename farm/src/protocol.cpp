#include "tessera/farm/protocol.h"

#include "tessera/farm/sha256.h"

#include <cstdlib>
#include <fstream>
#include <set>
#include <stdexcept>

namespace tessera {
namespace {

using nlohmann::json;

// Strict field reader: records the first error, names the field and what it should have been.
class Fields {
 public:
  Fields(const json& j, std::string& error, const char* what) : j_(j), error_(error), what_(what) {
    if (!j.is_object()) fail(std::string(what) + ": expected a JSON object");
  }
  bool ok() const { return error_.empty(); }

  template <class T>
  void get(const char* name, T& out, bool required = false) {
    seen_.insert(name);
    if (!ok()) return;
    auto it = j_.find(name);
    if (it == j_.end() || it->is_null()) {
      if (required) fail(std::string(what_) + ": missing field '" + name + "'");
      return;
    }
    try {
      if constexpr (std::is_same_v<T, bool>) {
        if (!it->is_boolean()) throw std::invalid_argument("true or false");
        out = it->template get<bool>();
      } else if constexpr (std::is_integral_v<T>) {
        if (!it->is_number_integer()) throw std::invalid_argument("an integer");
        const bool in_range =
            it->is_number_unsigned()
                ? it->template get<uint64_t>() <= uint64_t(std::numeric_limits<T>::max())
                : it->template get<int64_t>() >= int64_t(std::numeric_limits<T>::min()) &&
                      (it->template get<int64_t>() < 0 ||
                       uint64_t(it->template get<int64_t>()) <= uint64_t(std::numeric_limits<T>::max()));
        if (!in_range) throw std::invalid_argument("an integer in range");
        const int64_t v = it->is_number_unsigned() ? int64_t(it->template get<uint64_t>()) : it->template get<int64_t>();
        out = T(v);
      } else if constexpr (std::is_floating_point_v<T>) {
        if (!it->is_number()) throw std::invalid_argument("a number");
        out = it->template get<T>();
      } else if constexpr (std::is_same_v<T, std::string>) {
        if (!it->is_string()) throw std::invalid_argument("a string");
        out = it->template get<std::string>();
      } else {
        out = it->template get<T>();
      }
    } catch (const std::exception& e) {
      fail(std::string(what_) + ": field '" + name + "' must be " + e.what());
    }
  }
  /// Absent or null leaves `out` empty.
  template <class T>
  void get(const char* name, std::optional<T>& out) {
    T value{};
    const bool present = j_.is_object() && j_.contains(name) && !j_[name].is_null();
    get(name, value);
    if (present && ok()) out = value;
  }
  void get_strings(const char* name, std::map<std::string, std::string>& out) {
    seen_.insert(name);
    if (!ok()) return;
    auto it = j_.find(name);
    if (it == j_.end() || it->is_null()) return;
    if (!it->is_object()) return fail(std::string(what_) + ": field '" + name + "' must be an object of strings");
    for (auto& [k, v] : it->items()) {
      if (v.is_string()) out[k] = v.get<std::string>();
      else if (v.is_number() || v.is_boolean()) out[k] = v.dump();
      else return fail(std::string(what_) + ": field '" + name + "." + k + "' must be a string");
    }
  }
  void get_list(const char* name, std::vector<std::string>& out) {
    seen_.insert(name);
    if (!ok()) return;
    auto it = j_.find(name);
    if (it == j_.end() || it->is_null()) return;
    if (!it->is_array()) return fail(std::string(what_) + ": field '" + name + "' must be an array of strings");
    for (auto& v : *it) {
      if (!v.is_string()) return fail(std::string(what_) + ": field '" + name + "' must be an array of strings");
      out.push_back(v.get<std::string>());
    }
  }
  /// Unknown fields are errors: a misspelt "sp" must not render the scene's default spp.
  void finish() {
    if (!ok()) return;
    for (auto& [k, v] : j_.items())
      if (!seen_.count(k)) return fail(std::string(what_) + ": unknown field '" + k + "'");
  }
  void fail(const std::string& msg) {
    if (error_.empty()) error_ = msg;
  }

 private:
  const json& j_;
  std::string& error_;
  const char* what_;
  std::set<std::string> seen_;
};

}  // namespace

json to_json(const JobSettings& s) {
  json j = {{"name", s.name},   {"scene", s.scene},         {"scene_file", s.scene_file},
            {"spp", s.spp},     {"width", s.width},         {"height", s.height},
            {"seed", s.seed},   {"tile_size", s.tile_size}, {"priority", s.priority},
            {"defines", s.defines}, {"integrator", s.integrator}, {"light_selection", s.light_selection},
            {"target_error", s.target_error}, {"adaptive", s.adaptive}, {"denoise", s.denoise},
            {"webhook", s.webhook}};
  j["guiding"] = s.guiding ? json(*s.guiding) : json(nullptr);
  return j;
}

namespace {

// "12-20", "12..20", "7" or [12, 20]: an inclusive range.
bool parse_frames(const json& j, int& first, int& last, std::string& error) {
  try {
    if (j.is_array() && j.size() == 2 && j[0].is_number_integer() && j[1].is_number_integer()) {
      first = j[0].get<int>();
      last = j[1].get<int>();
    } else if (j.is_number_integer()) {
      first = last = j.get<int>();
    } else if (j.is_string()) {
      const std::string s = j.get<std::string>();
      size_t cut = s.find("..");
      size_t skip = 2;
      if (cut == std::string::npos) cut = s.find('-', 1), skip = 1;
      size_t used = 0;
      first = std::stoi(s.substr(0, cut), &used);
      if (used != (cut == std::string::npos ? s.size() : cut)) throw std::invalid_argument("trailing characters");
      last = first;
      if (cut != std::string::npos) {
        const std::string rest = s.substr(cut + skip);
        last = std::stoi(rest, &used);
        if (used != rest.size()) throw std::invalid_argument("trailing characters");
      }
    } else {
      throw std::invalid_argument("type");
    }
  } catch (const std::exception&) {
    error = "job settings: field 'frames' must be \"FIRST-LAST\", \"FIRST..LAST\", a frame number or [FIRST, LAST]";
    return false;
  }
  if (last < first) {
    error = "job settings: frames " + std::to_string(first) + ".." + std::to_string(last) + " ends before it starts";
    return false;
  }
  return true;
}

}  // namespace

bool job_request_from_json(const json& j, JobRequest& out, std::string& error, bool require_scene) {
  if (!j.is_object() || !j.contains("frames")) {
    out.frames.reset();
    return job_settings_from_json(j, out.settings, error, require_scene);
  }
  int first = 0, last = 0;
  if (!parse_frames(j["frames"], first, last, error)) return false;
  json settings = j;
  settings.erase("frames");
  out.frames = std::pair{first, last};
  return job_settings_from_json(settings, out.settings, error, require_scene);
}

bool job_settings_from_json(const json& j, JobSettings& out, std::string& error, bool require_scene) {
  Fields f(j, error, "job settings");
  f.get("name", out.name);
  f.get("scene", out.scene, require_scene);
  f.get("scene_file", out.scene_file);
  f.get("spp", out.spp);
  f.get("width", out.width);
  f.get("height", out.height);
  f.get("seed", out.seed);
  f.get("tile_size", out.tile_size);
  f.get("priority", out.priority);
  f.get_strings("defines", out.defines);
  f.get("integrator", out.integrator);
  f.get("light_selection", out.light_selection);
  f.get("target_error", out.target_error);
  f.get("adaptive", out.adaptive);
  f.get("guiding", out.guiding);
  f.get("denoise", out.denoise);
  f.get("webhook", out.webhook);
  f.finish();
  if (!f.ok()) return false;
  if (!out.scene.empty() && !is_sha256_hex(out.scene)) {
    error = "job settings: field 'scene' must be a bundle hash (64 lowercase hex digits)";
    return false;
  }
  if (!(out.target_error >= 0 && out.target_error <= 1)) {
    error = "job settings: field 'target_error' must be a relMSE in 0..1 (0: render every sample)";
    return false;
  }
  if (!out.webhook.empty() && ((out.webhook.rfind("http://", 0) != 0 && out.webhook.rfind("https://", 0) != 0) ||
                               out.webhook.size() > 2000)) {
    error = "job settings: field 'webhook' must be an http:// or https:// URL";
    return false;
  }
  if (out.name.size() > 200) {
    error = "job settings: field 'name' is longer than 200 characters";
    return false;
  }
  return true;
}

bool check_job_limits(const JobSettings& s, const JobLimits& l, std::string& error) {
  auto fail = [&](const std::string& m) {
    error = "job settings: " + m;
    return false;
  };
  if (s.spp < 0 || s.spp > l.max_spp) return fail("spp " + std::to_string(s.spp) + " is outside 1.." + std::to_string(l.max_spp));
  for (auto [name, v] : {std::pair{"width", s.width}, std::pair{"height", s.height}})
    if (v < 0 || v > l.max_resolution)
      return fail(std::string(name) + " " + std::to_string(v) + " is outside 1.." + std::to_string(l.max_resolution));
  if (int64_t(s.width) * s.height > l.max_pixels) return fail("the image has more than " + std::to_string(l.max_pixels) + " pixels");
  if (s.tile_size < l.min_tile_size || s.tile_size > l.max_tile_size)
    return fail("tile_size " + std::to_string(s.tile_size) + " is outside " + std::to_string(l.min_tile_size) + ".." +
                std::to_string(l.max_tile_size));
  if (s.width > 0 && s.height > 0 && s.tile_size > 0) {
    const int64_t tiles = int64_t((s.width + s.tile_size - 1) / s.tile_size) * ((s.height + s.tile_size - 1) / s.tile_size);
    if (tiles > l.max_tiles)
      return fail(std::to_string(tiles) + " tiles of " + std::to_string(s.tile_size) + " pixels exceed the limit of " +
                  std::to_string(l.max_tiles) + " tiles (use a larger tile_size)");
  }
  if (!s.integrator.empty() && s.integrator != "path" && s.integrator != "volpath" && s.integrator != "direct")
    return fail("integrator '" + s.integrator + "' is not path, volpath or direct");
  if (!s.light_selection.empty() && s.light_selection != "power" && s.light_selection != "bvh")
    return fail("light_selection '" + s.light_selection + "' is not power or bvh");
  return true;
}

namespace {

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
  json j = lease_own_json(l);
  j.update(lease_job_json(l));
  return j;
}

size_t lease_job_part_bytes(const Lease& l) { return lease_job_json(l).dump().size(); }

size_t lease_json_bytes(const Lease& l, size_t job_part_bytes) {
  // "{own}" and "{job}" make "{own,job}": one byte fewer than the two apart (the order of the
  // keys does not change the length).
  return lease_own_json(l).dump().size() + job_part_bytes - 1;
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
  if (out.rect.empty() || out.sample_end <= out.sample_begin) {
    error = "lease: empty rectangle or sample range";
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
  return sha256_hex(j.dump());
}

}  // namespace tessera
