// The farm's JSON messages (docs/api.md): job settings as submitted, a lease as handed to a
// worker, a worker's registration. Parsing is strict: unknown fields, wrong types and absurd values
// are errors naming the field, because a typo in a job must not silently render something else.
#pragma once

#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

/// What a client asks for. Zero sizes/spp mean "as the scene says".
struct JobSettings {
  std::string name;
  std::string scene;        // bundle hash (SHA-256 hex)
  std::string scene_file;   // the XML inside the bundle; empty: the single *.xml at its root
  int spp = 0, width = 0, height = 0;
  uint32_t seed = 0;
  int tile_size = 32;
  int priority = 0;         // higher first
  std::map<std::string, std::string> defines;
  std::string integrator;       // empty: the scene's
  std::string light_selection;  // empty: the default
  /// > 0: stop once the estimated relMSE of the image (noise_estimate.h) is at most this, at a
  /// pass boundary; `spp` is then the budget. The image equals `tessera render` at the spp reached.
  double target_error = 0;
  /// Adaptive sampling (render/adaptive.h): later passes spend the budget where the film's variance
  /// is. The farm decides each such pass's counts at its barrier, from the film, as render() does.
  bool adaptive = false;
  /// Path guiding: empty lets the scene decide (its guided_path integrator asks for it).
  std::optional<bool> guiding;
  /// Denoise the finished image (denoise/denoiser.h): units render the AOV sums too, and the job is
  /// done once the raw image (with its AOV layers) and the denoised one are stored.
  bool denoise = false;
  std::string denoise_mode;     // "full" or "preview" (denoise/denoiser.h); empty: full
  /// AOV layers the image's EXR carries beside it (render/aov.h: "albedo,normal", "all"); empty:
  /// none, or with `denoise` the denoiser's. Units then sum the AOVs too (sums_aovs()).
  std::string aovs;
  bool allow_unsupported = false;  // documented fallbacks for unsupported plugins (LoadOptions)
  std::string webhook;          // http(s) URL POSTed the job's status when it ends; empty: none

  /// Whether units render the AOV sums: for the denoiser, or for the layers asked for.
  bool sums_aovs() const { return denoise || !aovs.empty(); }
};

/// The name of a job that was not given one: its scene's folder, then the file's stem unless that
/// is the conventional "scene" (cornell-box/scene.xml -> "cornell-box", veach/mis.xml ->
/// "veach-mis"); a path without a folder gives the stem. Many scenes are all called scene.xml, so
/// the stem alone would name every job alike.
std::string default_job_name(const std::string& scene_path);

/// Limits a job must respect (the coordinator's flags).
struct JobLimits {
  int max_spp = 1 << 20;
  int max_resolution = 32768;  // per side
  int64_t max_pixels = int64_t(1) << 28;
  int max_tile_size = 1024, min_tile_size = 4;
  int64_t max_tiles = int64_t(1) << 20;  // per job (each tile is state on the coordinator)
};

nlohmann::json to_json(const JobSettings& s);
/// `j` must be an object; `require_scene` demands the `scene` field (not for multipart uploads).
/// `out_of_range` (if given) tells a number outside its field's range (the API's 422) from a
/// malformed request (400); the error names the field and the range.
[[nodiscard]] bool job_settings_from_json(const nlohmann::json& j, JobSettings& out, std::string& error,
                                          bool require_scene = true, bool* out_of_range = nullptr);

/// A submission: the job's settings and, for an animation, its inclusive frame range (one job per
/// frame N, with `-D frame=N`).
struct JobRequest {
  JobSettings settings;
  std::optional<std::pair<int, int>> frames;
};
/// The settings plus "frames": "FIRST-LAST", "FIRST..LAST", a frame number or [FIRST, LAST].
[[nodiscard]] bool job_request_from_json(const nlohmann::json& j, JobRequest& out, std::string& error,
                                         bool require_scene = true, bool* out_of_range = nullptr);

/// Range checks after the scene's defaults are known.
[[nodiscard]] bool check_job_limits(const JobSettings& s, const JobLimits& limits, std::string& error);

/// One unit of work: samples [sample_begin, sample_end) of every pixel of `rect`, or in an adaptive
/// pass the samples `samples` gives each pixel (sample_begin/end then name the pass's nominal range);
/// or, for a unit of a Paths pass (sequence/pass_program.h), the light paths `paths` ([begin, end)),
/// whose result covers `rect`, the whole window (farm/splat_result.h), and `tile` its index in the pass.
struct Lease {
  uint64_t id = 0;
  uint64_t job_id = 0;
  uint32_t tile = 0, pass = 0;
  TileRect rect;
  uint32_t sample_begin = 0, sample_end = 0;
  PassSamples samples;           // an adaptive pass's per-pixel samples over `rect`; else empty
  std::optional<std::pair<uint64_t, uint64_t>> paths;  // a Paths unit's light paths
  double seconds_to_expiry = 0;  // heartbeat before this
  JobSettings settings;          // the job's, with spp/width/height resolved
  std::string scene_file;        // resolved XML path inside the bundle
  std::vector<std::string> files;  // bundle files the scene references (the worker unpacks only these)
  /// A unit of a guided job's pass that samples or trains: the guide it renders with (GET
  /// /api/v1/guides/HASH), learned over `iteration` training passes, and whether it trains.
  struct Guide {
    std::string hash;  // SHA-256 hex of the guide's bytes (guide_artifact.h)
    uint32_t iteration = 0;
    bool train = false;
    bool operator==(const Guide&) const = default;
  };
  std::optional<Guide> guide;
  /// A Tile unit of a pass that starts from its tile's per-pixel state (PassSpec::tile_state: an
  /// sppm gather's radii, counts and flux): the bytes its tile's previous gather left ("tile_state",
  /// base64 on the wire).
  std::string tile_state;
};

/// A lease's tile state is at most this many bytes (a largest tile's SppmPixels).
inline constexpr size_t kMaxLeaseStateBytes = size_t(1024) * 1024 * 32;

nlohmann::json to_json(const Lease& l);
/// Bytes of to_json(l).dump() without serializing the job's part of it again: `job_part_bytes` is
/// lease_job_part_bytes() of any lease of the same job (its settings, scene file and files).
size_t lease_json_bytes(const Lease& l, size_t job_part_bytes);
size_t lease_job_part_bytes(const Lease& l);
[[nodiscard]] bool lease_from_json(const nlohmann::json& j, Lease& out, std::string& error);

struct WorkerHello {
  std::string name;
  int threads = 1;
  uint64_t memory_bytes = 0;
  std::string version, isa, probe;  // build_fingerprint.h
};

nlohmann::json to_json(const WorkerHello& h);
[[nodiscard]] bool worker_hello_from_json(const nlohmann::json& j, WorkerHello& out, std::string& error);

/// What the coordinator tells a worker at registration.
struct Registration {
  uint64_t id = 0;
  double lease_timeout = 0, heartbeat_seconds = 0, max_poll_wait = 0;
};

nlohmann::json to_json(const Registration& r);

/// The answer to a tile result: accepted (stored, or the same worker's earlier copy was), or a
/// duplicate of another worker's; with the worker's next lease when it asked for one ("lease", null
/// when there is no work for it now).
struct ResultAck {
  bool accepted = false, duplicate = false;
  bool next_asked = false;
  std::optional<Lease> next;
};

nlohmann::json to_json(const ResultAck& a);

/// A lease a worker still holds, as its heartbeat reports it ({"leases": [...]}).
struct HeldLease {
  uint64_t id = 0, job = 0;
  uint32_t tile = 0, pass = 0;
};

/// A worker never holds more leases than this (one per thread): a longer heartbeat is refused.
inline constexpr size_t kMaxHeldLeases = 4096;

/// What a worker holds in memory: the scenes (and guides) loaded in its cache, measured as
/// Scene::memory counts them (BVHs, meshes, images), and how many.
struct WorkerMemory {
  uint64_t scene_bytes = 0;
  uint32_t scenes = 0;
};

/// A worker's heartbeat: the leases it holds and, from workers that report it, its memory.
struct Heartbeat {
  std::vector<HeldLease> leases;
  std::optional<WorkerMemory> memory;
};

nlohmann::json heartbeat_to_json(const Heartbeat& h);
/// Strict: {"leases": [{"id", "job", "tile", "pass"}, ...], "memory": {"scene_bytes", "scenes"}}
/// (both optional) and nothing else.
[[nodiscard]] bool heartbeat_from_json(const nlohmann::json& j, Heartbeat& out, std::string& error);

/// A bearer token from a flag, a file or the environment, in that order of precedence: `flag`,
/// else the first line of `file`, else $`env_var` (empty when none is set). Throws
/// std::runtime_error naming an unreadable or empty file.
std::string resolve_token(const std::string& flag, const std::string& file, const char* env_var);

/// The key under which a worker caches a loaded scene: everything that changes what load_scene
/// builds (bundle, XML, defines, size, spp, integrator, light selection).
std::string scene_cache_key(const JobSettings& resolved, const std::string& scene_file);

}  // namespace tessera
