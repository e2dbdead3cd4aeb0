// Job settings as JSON: the fields a submission may hold, their types and ranges (422 for a value out
// of range, 400 for a malformed request), frame ranges, a job's default name and the coordinator's
// limits.
#include "json_fields.h"
#include "tessera/farm/protocol.h"
#include "tessera/farm/sha256.h"
#include "tessera/render/aov.h"

#include <filesystem>
#include <stdexcept>

namespace tessera {

using nlohmann::json;
using json_fields::Fields;

json to_json(const JobSettings& s) {
  json j = {{"name", s.name},   {"scene", s.scene},         {"scene_file", s.scene_file},
            {"spp", s.spp},     {"width", s.width},         {"height", s.height},
            {"seed", s.seed},   {"tile_size", s.tile_size}, {"priority", s.priority},
            {"defines", s.defines}, {"integrator", s.integrator}, {"light_selection", s.light_selection},
            {"target_error", s.target_error}, {"adaptive", s.adaptive}, {"denoise", s.denoise},
            {"denoise_mode", s.denoise_mode}, {"aovs", s.aovs}, {"allow_unsupported", s.allow_unsupported},
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

bool job_request_from_json(const json& j, JobRequest& out, std::string& error, bool require_scene,
                           bool* out_of_range) {
  if (!j.is_object() || !j.contains("frames")) {
    out.frames.reset();
    return job_settings_from_json(j, out.settings, error, require_scene, out_of_range);
  }
  int first = 0, last = 0;
  if (!parse_frames(j["frames"], first, last, error)) return false;
  json settings = j;
  settings.erase("frames");
  out.frames = std::pair{first, last};
  return job_settings_from_json(settings, out.settings, error, require_scene, out_of_range);
}

namespace {

// The checks of the fields' values once each has its type; false with the error set.
bool job_values_valid(const JobSettings& out, std::string& error, bool& out_of_range) {
  if (!out.scene.empty() && !is_sha256_hex(out.scene)) {
    error = "job settings: field 'scene' must be a bundle hash (64 lowercase hex digits)";
    return false;
  }
  if (!(out.target_error >= 0 && out.target_error <= 1)) {
    out_of_range = true;
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
  if (!out.denoise_mode.empty() && out.denoise_mode != "full" && out.denoise_mode != "preview") {
    error = "job settings: field 'denoise_mode' must be full or preview";
    return false;
  }
  std::string aov_error;
  if (!out.aovs.empty() && !parse_aov_layers(out.aovs, &aov_error)) {
    error = "job settings: field 'aovs': " + aov_error;
    return false;
  }
  return true;
}

}  // namespace

bool job_settings_from_json(const json& j, JobSettings& out, std::string& error, bool require_scene,
                            bool* out_of_range) {
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
  f.get("denoise_mode", out.denoise_mode);
  f.get("aovs", out.aovs);
  f.get("allow_unsupported", out.allow_unsupported);
  f.finish();
  bool range = f.out_of_range();
  const bool valid = f.ok() && job_values_valid(out, error, range);
  if (out_of_range) *out_of_range = range;
  return valid;
}

std::string default_job_name(const std::string& scene_path) {
  const std::filesystem::path path(scene_path);
  const std::string stem = path.stem().string(), folder = path.parent_path().filename().string();
  const std::string name = folder.empty() || folder == "." || folder == ".." ? stem
                           : stem == "scene" || stem == folder             ? folder
                                                                            : folder + "-" + stem;
  return name.substr(0, 200);
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
  // The names LoadOptions::integrator takes; checked here so that a typo is refused before a bundle is read.
  const std::string& i = s.integrator;
  if (!i.empty() && i != "path" && i != "volpath" && i != "direct" && i != "bdpt" && i != "ptracer" && i != "sppm" &&
      i != "vcm")
    return fail("integrator '" + i + "' is not path, volpath, direct, bdpt, ptracer, sppm or vcm");
  if (!s.light_selection.empty() && s.light_selection != "power" && s.light_selection != "bvh")
    return fail("light_selection '" + s.light_selection + "' is not power or bvh");
  return true;
}

}  // namespace tessera
