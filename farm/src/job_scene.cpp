#include "tessera/farm/job_scene.h"

#include "tessera/farm/bundle.h"
#include "tessera/farm/program_json.h"
#include "tessera/guiding/tree_io.h"
#include "tessera/render/aov.h"
#include "tessera/render/bdpt.h"
#include "tessera/render/light_sampler.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

namespace tessera {

namespace fs = std::filesystem;

LoadedJobScene load_job_scene(const std::string& bundle_dir, const std::string& scene_file,
                              const JobSettings& settings, bool confine) {
  ParseOptions parse_options;
  parse_options.defines = settings.defines;
  if (confine) parse_options.root_dir = bundle_dir;
  LoadedJobScene out;
  out.desc = parse_scene_file((fs::path(bundle_dir) / scene_file).string(), parse_options);
  LoadOptions load_options;
  load_options.width = settings.width;
  load_options.height = settings.height;
  load_options.spp = settings.spp;
  load_options.integrator = settings.integrator;
  load_options.allow_unsupported = settings.allow_unsupported;
  if (confine) load_options.root_dir = bundle_dir;
  out.loaded = load_scene(out.desc, load_options);
  if (!settings.light_selection.empty()) {
    LightSelection selection;
    if (!parse_light_selection(settings.light_selection, selection))
      throw SceneError(FileLoc{scene_file, 0}, "unknown light selection '" + settings.light_selection + "'");
    out.loaded.scene->set_light_selection(selection);
  }
  return out;
}

JobPlan make_job_plan(const std::string& bundle_dir, const std::string& scene_file, const JobSettings& settings,
                      const LoadedJobScene& scene) {
  const Scene& s = *scene.loaded.scene;
  JobPlan plan;
  plan.guide = guide_plan(s, settings.guiding);  // (as `tessera render` guides)
  plan.settings = settings;
  plan.settings.spp = s.sampler.sample_count;
  plan.settings.width = s.film.width;
  plan.settings.height = s.film.height;
  plan.scene_file = scene_file;
  plan.window = film_window(s.film);
  plan.full_width = s.film.width;
  plan.full_height = s.film.height;
  plan.ldr = s.film.ldr;
  plan.gamma = s.film.gamma;
  plan.exposure = s.film.exposure;
  const fs::path root = fs::weakly_canonical(bundle_dir);
  for (const std::string& f : scene_files(scene.desc, scene.loaded)) {
    std::string rel = fs::weakly_canonical(f).lexically_relative(root).generic_string();
    if (rel.empty() || rel.rfind("..", 0) == 0)
      throw SceneError(FileLoc{scene_file, 0}, "the scene references '" + f + "', which is outside its bundle");
    if (std::find(plan.files.begin(), plan.files.end(), rel) == plan.files.end()) plan.files.push_back(rel);
  }
  if (std::string e = technique_settings_error(s.integrator.type, settings.sums_aovs(), settings.target_error,
                                               settings.adaptive, settings.guiding.value_or(false));
      !e.empty())
    throw std::invalid_argument(e);
  if (uses_light_vertex_passes(s.integrator.type)) {
    plan.points = point_map_plan(s);
    plan.program = light_vertex_program(s, uint32_t(plan.settings.spp), uint64_t(plan.window.area()));
    return plan;
  }
  PathProgramOptions options = path_options(plan);
  options.light_paths = traces_light_paths(s.integrator);
  plan.program = path_program(options);
  return plan;
}

PathProgramOptions path_options(const JobPlan& plan) {
  return {uint32_t(plan.settings.spp), plan.settings.target_error, plan.settings.adaptive, AdaptiveSettings{}, plan.guide};
}

PassProgram job_program(const JobPlan& plan) {
  return plan.program.passes.empty() ? path_program(path_options(plan)) : plan.program;
}

void keep_job_exr_layers(const JobSettings& settings, std::vector<ImageLayer>& layers) {
  if (settings.aovs.empty()) {
    if (!settings.denoise) layers.clear();
    return;
  }
  const std::vector<AovLayer> wanted = parse_aov_layers(settings.aovs).value_or(std::vector<AovLayer>{});
  std::erase_if(layers, [&](const ImageLayer& l) {
    return std::none_of(wanted.begin(), wanted.end(), [&](AovLayer a) { return l.name == aov_layer_name(a); });
  });
}

void begin_tile_result(const Lease& lease, TileResult& out) {
  out.job_id = lease.job_id;
  out.tile = lease.tile;
  out.pass = lease.pass;
  out.sample_begin = lease.sample_begin;
  out.sample_end = lease.sample_end;
  out.seconds = 0;
  out.film.reset(lease.rect);
}

TileResult render_lease(const Scene& scene, const Lease& lease, const SpatialTree* guide) {
  TileResult result;
  begin_tile_result(lease, result);
  const auto t0 = std::chrono::steady_clock::now();
  const PassSamples samples = lease.samples.count.empty()
                                  ? PassSamples::uniform(lease.rect, lease.sample_begin, lease.sample_end)
                                  : lease.samples;
  if (lease.guide && !guide) throw std::invalid_argument("render_lease: a guided lease without its guide");
  // (The path tracer's passes are Tile passes; a technique that traces light paths renders those.)
  if (lease.paths) throw std::invalid_argument("render_lease: a lease of light paths (render_paths_lease renders those)");
  // Training goes into a recorder of the guide, whose nonzero sums travel with the result.
  std::optional<SpatialTree> recorder;
  if (lease.guide && lease.guide->train) recorder = make_recorder(*guide);
  std::optional<PathGuide> path_guide;
  if (lease.guide) {
    // (The job's guide settings are the scene's, as guide_plan() made them at submission.)
    const std::optional<GuidePlan> plan = guide_plan(scene, true);
    if (!plan) throw std::invalid_argument("render_lease: a guided lease of a scene that cannot be guided");
    path_guide = PathGuide::of(guide, recorder ? &*recorder : nullptr, lease.guide->iteration > 0, lease.guide->train,
                               plan->settings);
  }
  // A denoised job's units, or one's with AOV layers, also sum the AOVs.
  render_tile(scene, lease.rect, samples, lease.settings.seed, result.film, path_guide ? &*path_guide : nullptr,
              lease.settings.sums_aovs());
  if (recorder) result.training = write_records(*recorder);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

SplatResult render_paths_lease(const Scene& scene, const Lease& lease) {
  if (!lease.paths) throw std::invalid_argument("render_paths_lease: a lease of a tile");
  if (!traces_light_paths(scene.integrator))
    throw std::invalid_argument("render_paths_lease: the scene's integrator traces no light paths");
  const auto t0 = std::chrono::steady_clock::now();
  SplatResult r;
  r.job_id = lease.job_id;
  r.pass = lease.pass;
  r.unit = lease.tile;
  r.path_begin = lease.paths->first;
  r.path_end = lease.paths->second;
  render_light_unit(scene, r.path_begin, r.path_end, lease.settings.seed, r.splats);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

// The unit a lease of a light-vertex job names, as the sequencer gave it to the coordinator.
UnitWork lease_work(const Lease& lease) {
  UnitWork w;
  w.pass = lease.pass;
  w.index = lease.tile;
  w.kind = lease.paths ? UnitKind::Paths : UnitKind::Tile;
  w.rect = lease.rect;
  w.sample_begin = lease.sample_begin;
  w.sample_end = lease.sample_end;
  if (lease.paths) {
    w.path_begin = lease.paths->first;
    w.path_end = lease.paths->second;
    w.feeds = lease.sample_begin;  // (every light pass of a program with maps feeds one)
  }
  if (lease.guide) w.uses = lease.guide->iteration;
  if (!lease.tile_state.empty()) w.tile_state = &lease.tile_state;
  return w;
}

}  // namespace

TileResult render_light_vertex_tile(const Scene& scene, const Lease& lease, const Artifact* points) {
  if (lease.paths || !uses_light_vertex_passes(scene.integrator.type))
    throw std::invalid_argument("render_light_vertex_tile: not a tile of an sppm or vcm job");
  if (lease.guide && !points) throw std::invalid_argument("render_light_vertex_tile: a lease without its map");
  const auto t0 = std::chrono::steady_clock::now();
  UnitResult unit;
  unit.tile.reset(lease.rect);
  render_light_vertex_unit(scene, points, lease_work(lease), lease.settings.seed, unit);
  TileResult r;
  begin_tile_result(lease, r);
  r.film = std::move(unit.tile);
  r.tile_state = std::move(unit.tile_state);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

SplatResult render_light_vertex_paths(const Scene& scene, const Lease& lease) {
  if (!lease.paths || !uses_light_vertex_passes(scene.integrator.type))
    throw std::invalid_argument("render_light_vertex_paths: not a lease of light paths of an sppm or vcm job");
  const auto t0 = std::chrono::steady_clock::now();
  UnitResult unit;
  UnitWork work = lease_work(lease);
  if (!point_map_plan(scene)) work.feeds.reset();  // (vcm without merging: bdpt's light paths)
  render_light_vertex_unit(scene, nullptr, work, lease.settings.seed, unit);
  SplatResult r;
  r.job_id = lease.job_id;
  r.pass = lease.pass;
  r.unit = lease.tile;
  r.path_begin = work.path_begin;
  r.path_end = work.path_end;
  r.splats = std::move(unit.splats);
  r.records = std::move(unit.records);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

using nlohmann::json;

json points_json(const PointMapPlan& p) {
  return {{"integrator", integrator_name(p.type)}, {"initial_radius", p.initial_radius}, {"alpha", p.alpha}};
}

PointMapPlan points_from_json(const json& j) {
  PointMapPlan p;
  const std::string type = j.at("integrator").get<std::string>();
  if (type != "sppm" && type != "vcm") throw std::invalid_argument("points: integrator '" + type + "'");
  p.type = type == "sppm" ? IntegratorType::Sppm : IntegratorType::Vcm;
  p.initial_radius = j.at("initial_radius").get<float>();
  p.alpha = j.at("alpha").get<float>();
  if (!(p.initial_radius > 0.f) || !std::isfinite(p.initial_radius) || !(p.alpha > 0.f && p.alpha <= 1.f))
    throw std::invalid_argument("points: radius or alpha out of range");
  return p;
}

json guide_json(const JobPlan::Guide& g) {
  const GuidingSettings& s = g.settings;
  return {{"bounds", {g.bounds.lo.x, g.bounds.lo.y, g.bounds.lo.z, g.bounds.hi.x, g.bounds.hi.y, g.bounds.hi.z}},
          {"spatial_threshold", s.spatial_threshold},
          {"directional_threshold", s.directional_threshold},
          {"max_bytes", s.max_bytes},
          {"bsdf_fraction", s.bsdf_fraction},
          {"learn_bsdf_fraction", s.learn_bsdf_fraction},
          {"min_bsdf_fraction", s.min_bsdf_fraction},
          {"keep_energy", s.keep_energy},
          {"combination", guide_combination_name(s.combination)},
          {"combined_iterations", s.combined_iterations},
          {"roulette", guide_roulette_name(s.roulette)},
          {"spatial_filter", spatial_filter_name(s.spatial_filter)},
          {"directional_filter", directional_filter_name(s.directional_filter)},
          {"min_gain", s.min_gain},
          {"gain_iteration_spp", s.gain_iteration_spp},
          {"gain_paths", s.gain_paths}};
}

JobPlan::Guide guide_from_json(const json& j) {
  JobPlan::Guide g;
  const auto b = j.at("bounds").get<std::vector<float>>();
  if (b.size() != 6) throw std::invalid_argument("guide bounds");
  g.bounds.lo = Vec3(b[0], b[1], b[2]);
  g.bounds.hi = Vec3(b[3], b[4], b[5]);
  GuidingSettings& s = g.settings;
  s.spatial_threshold = j.at("spatial_threshold").get<double>();
  s.directional_threshold = j.at("directional_threshold").get<double>();
  s.max_bytes = j.at("max_bytes").get<size_t>();
  s.bsdf_fraction = j.at("bsdf_fraction").get<float>();
  s.learn_bsdf_fraction = j.at("learn_bsdf_fraction").get<bool>();
  s.min_bsdf_fraction = j.at("min_bsdf_fraction").get<float>();
  s.keep_energy = j.at("keep_energy").get<bool>();
  // (A plan stored before these three were settings rendered as they now name Discard and Throughput.)
  const std::string combination = j.value("combination", guide_combination_name(GuideCombination::Discard));
  const std::string roulette = j.value("roulette", guide_roulette_name(GuideRoulette::Throughput));
  if (combination != "discard" && combination != "inversevar") throw std::invalid_argument("guide combination");
  if (!parse_guide_roulette(roulette, s.roulette)) throw std::invalid_argument("guide roulette");
  s.combination = combination == "discard" ? GuideCombination::Discard : GuideCombination::InverseVariance;
  s.combined_iterations = j.value("combined_iterations", 4);
  if (!parse_spatial_filter(j.value("spatial_filter", "nearest"), s.spatial_filter))
    throw std::invalid_argument("guide spatial_filter");
  if (!parse_directional_filter(j.value("directional_filter", "nearest"), s.directional_filter))
    throw std::invalid_argument("guide directional_filter");
  if (s.combined_iterations < 1) throw std::invalid_argument("guide combined_iterations");
  // (A plan stored before guiding could step aside never did.)
  s.min_gain = j.value("min_gain", 0.0);
  s.gain_iteration_spp = j.value("gain_iteration_spp", s.gain_iteration_spp);
  s.gain_paths = j.value("gain_paths", s.gain_paths);
  if (!(s.min_gain >= 0.0) || s.gain_paths < 1) throw std::invalid_argument("guide min_gain or gain_paths");
  return g;
}

}  // namespace

nlohmann::json to_json(const JobPlan& p) {
  return {{"settings", to_json(p.settings)},
          {"scene_file", p.scene_file},
          {"files", p.files},
          {"window", {p.window.x0, p.window.y0, p.window.x1, p.window.y1}},
          {"full_width", p.full_width},
          {"full_height", p.full_height},
          {"ldr", p.ldr},
          {"gamma", p.gamma},
          {"exposure", p.exposure},
          {"guide", p.guide ? guide_json(*p.guide) : json(nullptr)},
          {"points", p.points ? points_json(*p.points) : json(nullptr)},
          {"program", to_json(p.program)}};
}

bool job_plan_from_json(const nlohmann::json& j, JobPlan& out, std::string& error) {
  try {
    if (!job_settings_from_json(j.at("settings"), out.settings, error)) return false;
    out.scene_file = j.at("scene_file").get<std::string>();
    out.files = j.at("files").get<std::vector<std::string>>();
    auto w = j.at("window").get<std::vector<int>>();
    if (w.size() != 4) throw std::invalid_argument("window");
    out.window = {w[0], w[1], w[2], w[3]};
    out.full_width = j.at("full_width").get<int>();
    out.full_height = j.at("full_height").get<int>();
    out.ldr = j.at("ldr").get<bool>();
    out.gamma = j.at("gamma").get<float>();
    out.exposure = j.at("exposure").get<float>();
    out.guide.reset();
    if (j.contains("guide") && !j["guide"].is_null()) out.guide = guide_from_json(j["guide"]);
    out.points.reset();
    if (j.contains("points") && !j["points"].is_null()) out.points = points_from_json(j["points"]);
    // (A plan stored before programs were kept has none: its settings give it, job_program().)
    out.program = PassProgram{};
    if (j.contains("program") && !program_from_json(j["program"], out.program, error)) return false;
    return true;
  } catch (const std::exception& e) {
    error = std::string("job plan: ") + e.what();
    return false;
  }
}

}  // namespace tessera
