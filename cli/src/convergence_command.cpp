// `tessera bench convergence`: load once, then per strategy render at each budget and measure the
// error against the reference (convergence.h).
#include "tessera/cli/command_line.h"
#include "tessera/cli/convergence.h"
#include "tessera/image/image.h"
#include "tessera/render/integrator.h"
#include "tessera/render/noise_estimate.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <tbb/info.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace tessera::cli {
namespace {

constexpr int kMaxSpp = 65536;

bool write_text(const std::string& path, const std::string& text) {
  auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path, std::ios::binary);
  out << text;
  return bool(out);
}

void print_time_to_target(const std::string& strategy, const std::vector<ConvergencePoint>& points, double target) {
  TimeToTarget t = time_to_target(points, target);
  if (!t.reached)
    std::printf("time_to_target strategy=%s relmse=%g not reached\n", strategy.c_str(), target);
  else if (t.at_first_budget)
    std::printf("time_to_target strategy=%s relmse=%g seconds<=%.4g (reached at the first budget)\n",
                strategy.c_str(), target, t.seconds);
  else
    std::printf("time_to_target strategy=%s relmse=%g seconds=%.4g\n", strategy.c_str(), target, t.seconds);
}

// A series: a strategy, with or without guiding and adaptive sampling, named e.g. "mis",
// "mis+guiding" or "mis+guiding+adaptive".
struct Series {
  std::string name;
  SamplingStrategy strategy;
  bool guiding, adaptive;
};

// Every series the options ask for; none (the reason printed) for an unknown strategy.
std::optional<std::vector<Series>> plan_series(const ConvergenceOptions& options) {
  std::vector<Series> series;
  const auto or_off = [](const std::vector<std::string>& v) { return v.empty() ? std::vector<std::string>{"off"} : v; };
  const std::vector<std::string> guiding = or_off(options.guiding), adaptive = or_off(options.adaptive);
  for (const auto& name : options.strategies.empty() ? std::vector<std::string>{"mis"} : options.strategies) {
    SamplingStrategy s;
    if (!parse_sampling_strategy(name, s)) {
      std::fprintf(stderr, "tessera bench convergence: unknown strategy '%s' (use mis, bsdf, nee)\n", name.c_str());
      return std::nullopt;
    }
    for (const auto& g : guiding)
      for (const auto& a : adaptive)
        series.push_back({name + (g == "on" ? "+guiding" : "") + (a == "on" ? "+adaptive" : ""), s, g == "on", a == "on"});
  }
  return series;
}

// One series at every budget (then doubling while --seconds asks), each point printed.
std::vector<ConvergencePoint> run_series(const ConvergenceOptions& options, Scene& scene, RenderSettings settings,
                                         const Series& one, const std::vector<int>& budgets, const Image& ref) {
  scene.integrator.strategy = one.strategy;
  settings.guiding = one.guiding;
  settings.adaptive = one.adaptive;
  std::vector<ConvergencePoint> mine;
  auto run_budget = [&](size_t index, int spp) {
    settings.spp = spp;
    settings.seed = options.seed + uint32_t(index);
    RenderStats stats;
    Film film = render(scene, settings, {}, &stats);
    ConvergencePoint p;
    p.strategy = one.name;
    p.spp = spp;
    p.seconds = stats.seconds;
    p.error = measure_error(film.to_image().to_rgb(), ref);
    p.noise_estimate = estimate_noise(film).rel_mse;
    std::printf("strategy=%s spp=%d seconds=%.4f relmse=%.5g relmse_trim=%.5g mse=%.5g mean_ratio=%.5f "
                "noise_estimate=%.5g\n",
                p.strategy.c_str(), p.spp, p.seconds, p.error.rel_mse, p.error.rel_mse_trim, p.error.mse,
                p.error.mean_ratio, p.noise_estimate);
    std::fflush(stdout);
    mine.push_back(p);
  };
  for (size_t i = 0; i < budgets.size(); ++i) run_budget(i, budgets[i]);
  if (options.seconds > 0)
    for (int spp = budgets.empty() ? 1 : budgets.back() * 2;
         spp <= kMaxSpp && (mine.empty() || mine.back().seconds < options.seconds); spp *= 2)
      run_budget(mine.size(), spp);
  for (double target : {1e-2, 1e-3}) print_time_to_target(one.name, mine, target);
  return mine;
}

// The CSV and the SVG plot the options ask for; false (the reason printed) if one cannot be written.
bool write_results(const ConvergenceOptions& options, const std::vector<ConvergencePoint>& all, int w, int h,
                   int threads) {
  if (!options.csv.empty()) {
    std::ostringstream csv;
    write_convergence_csv(csv, all);
    if (!write_text(options.csv, csv.str())) {
      std::fprintf(stderr, "error: cannot write %s\n", options.csv.c_str());
      return false;
    }
    std::fprintf(stderr, "wrote %s\n", options.csv.c_str());
  }
  if (options.plot.empty()) return true;
  std::string title = std::filesystem::path(options.scene).parent_path().filename().string();
  if (title.empty()) title = options.scene;
  // (snprintf rather than string concatenation: GCC 12 warns falsely on the latter, -Wrestrict)
  char suffix[96];
  std::snprintf(suffix, sizeof suffix, " %dx%d, %d threads: relMSE against the reference", w, h, threads);
  title += suffix;
  if (!write_text(options.plot, convergence_svg(all, title))) {
    std::fprintf(stderr, "error: cannot write %s\n", options.plot.c_str());
    return false;
  }
  std::fprintf(stderr, "wrote %s\n", options.plot.c_str());
  return true;
}

// The scene, at the reference's size; throws if it cannot be loaded or does not match.
LoadResult load_for_reference(const ConvergenceOptions& options, const Image& ref) {
  LoadOptions load;
  load.allow_unsupported = options.allow_unsupported;
  load.width = options.width;
  load.height = options.height;
  load.integrator = options.integrator;
  LoadResult loaded = load_scene(parse_scene_file(options.scene), load);
  for (const auto& m : loaded.messages)
    if (m.level == LoadMessage::Level::Warning) std::cerr << "warning: " << m.loc.str() << ": " << m.text << "\n";
  const int w = loaded.scene->film.crop_w(), h = loaded.scene->film.crop_h();
  if (w != ref.width() || h != ref.height())
    throw std::runtime_error("the reference " + options.reference + " is " + std::to_string(ref.width()) + "x" +
                             std::to_string(ref.height()) + " but the render is " + std::to_string(w) + "x" +
                             std::to_string(h) + " (" +
                             (options.width > 0 || options.height > 0 ? "--width/--height"
                                                                      : "the scene's film; use --width/--height") +
                             ")");
  // The strategies are how path/volpath estimate direct light; the other integrators ignore them.
  const IntegratorType type = loaded.scene->integrator.type;
  if (type != IntegratorType::Path && type != IntegratorType::VolPath)
    std::fprintf(stderr, "note: the scene uses the %s integrator, which has no strategies: all equal\n",
                 integrator_name(type));
  return loaded;
}

}  // namespace

int run_bench_convergence(const ConvergenceOptions& options) {
  const std::optional<std::vector<Series>> series = plan_series(options);
  if (!series) return 2;
  std::vector<int> budgets = options.spp;
  if (budgets.empty() && options.seconds <= 0) budgets = {1, 2, 4, 8, 16, 32, 64};
  for (int spp : budgets)
    if (spp <= 0 || spp > kMaxSpp) {
      std::fprintf(stderr, "tessera bench convergence: --spp values must be in 1..%d\n", kMaxSpp);
      return 2;
    }
  try {
    const Image ref = read_image(options.reference).to_rgb();
    LoadResult loaded = load_for_reference(options, ref);
    Scene& scene = *loaded.scene;
    RenderSettings settings;
    settings.threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
    // Warm up threads and caches so the first timed render is not charged for them.
    settings.spp = 1;
    settings.seed = options.seed;
    (void)render(scene, settings);
    std::printf("convergence scene=%s %dx%d threads=%d\n", options.scene.c_str(), ref.width(), ref.height(),
                settings.threads);
    std::vector<ConvergencePoint> all;
    for (const Series& one : *series) {
      std::vector<ConvergencePoint> mine = run_series(options, scene, settings, one, budgets, ref);
      all.insert(all.end(), mine.begin(), mine.end());
    }
    return write_results(options, all, ref.width(), ref.height(), settings.threads) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

Command add_convergence_command(CLI::App& bench) {
  auto o = std::make_shared<ConvergenceOptions>();
  CLI::App* bc = bench.add_subcommand("convergence", "relMSE against a reference as the budget grows, per strategy (CSV, SVG)");
  bc->add_option("scene", o->scene, "Scene file")->required()->check(CLI::ExistingFile);
  bc->add_option("--reference", o->reference, "Reference image (.exr/.pfm/.hdr) of the same size")->required()
      ->check(CLI::ExistingFile);
  bc->add_option("--spp", o->spp, "Budgets, e.g. 1,2,4,8 (default 1..64 doubling)")->delimiter(',');
  bc->add_option("--seconds", o->seconds, "Then keep doubling spp until one render takes this long")
      ->check(CLI::NonNegativeNumber);
  bc->add_option("--guiding", o->guiding, "Path guiding, e.g. off,on: each strategy with each (default off); "
                 "guided series are named STRATEGY+guiding")->delimiter(',')->check(CLI::IsMember({"off", "on"}));
  bc->add_option("--adaptive", o->adaptive, "Adaptive sampling, e.g. off,on: each series with each (default off); "
                 "adaptive series are named SERIES+adaptive")->delimiter(',')->check(CLI::IsMember({"off", "on"}));
  bc->add_option("--strategy", o->strategies, "Sampling strategies: mis, bsdf, nee (default mis)")->delimiter(',')
      ->check(CLI::IsMember({"mis", "bsdf", "nee"}));
  bc->add_option("--csv", o->csv, "Write the measurements here");
  bc->add_option("--plot", o->plot, "Write an SVG plot here (log-log relMSE against seconds and spp)");
  bc->add_option("--width", o->width, "Film width (default: the scene's)")->check(CLI::PositiveNumber);
  bc->add_option("--height", o->height, "Film height (default: the scene's)")->check(CLI::PositiveNumber);
  bc->add_option("--threads", o->threads, "Render threads (default: all cores)")->check(CLI::NonNegativeNumber);
  bc->add_option("--seed", o->seed, "Seed of the first budget (budget i uses seed + i)");
  add_integrator_option(*bc, o->integrator);
  bc->add_flag("--allow-unsupported", o->allow_unsupported, "Substitute documented fallbacks for unsupported plugins");
  return {bc, [o] { return run_bench_convergence(*o); }};
}

}  // namespace tessera::cli
