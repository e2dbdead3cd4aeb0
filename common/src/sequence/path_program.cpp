#include "tessera/sequence/path_program.h"

#include "tessera/sequence/guide_training.h"
#include "tessera/sequence/pass_schedule.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace tessera {

std::optional<GuidePlan> guide_plan(const Scene& scene, std::optional<bool> requested,
                                    const std::optional<GuidingSettings>& settings) {
  if (!requested.value_or(scene.integrator.guiding.has_value()) || scene.integrator.type == IntegratorType::Direct ||
      scene.bounds().empty())
    return std::nullopt;
  return GuidePlan{scene.bounds(), settings.value_or(scene.integrator.guiding.value_or(GuidingSettings{}))};
}

std::string path_program_error(const PathProgramOptions& o) {
  if (!o.light_paths) return {};
  const char* what = o.target_error > 0 ? "a target error" : o.adaptive ? "adaptive sampling" : o.guide ? "path guiding" : nullptr;
  if (!what) return {};
  return std::string("this integrator traces light paths onto the film, whose noise is not in a pixel's own samples: ") +
         what + " needs the path tracer (integrator path or volpath)";
}

namespace {

// A pass's samples and, in a guided render, its iteration (-1 unguided).
struct PlannedPass {
  uint32_t samples = 0;
  int iteration = -1;
};

std::vector<PlannedPass> planned_passes(uint32_t spp, bool guided) {
  std::vector<PlannedPass> out;
  const std::vector<uint32_t> iterations = guided ? guide_iterations(spp) : std::vector<uint32_t>{};
  if (iterations.size() < 2) {  // (nothing would train: unguided)
    for (uint32_t n : pass_schedule(spp)) out.push_back({n, -1});
    return out;
  }
  for (size_t k = 0; k < iterations.size(); ++k)
    for (uint32_t n : iteration_passes(iterations[k])) out.push_back({n, int(k)});
  return out;
}

// Which film iteration k of n enters, and how many films there are.
int iteration_film(const GuidingSettings& g, int k, int n) {
  const int films = g.combination == GuideCombination::Discard ? 1 : std::clamp(g.combined_iterations, 1, n);
  return k >= n - films ? k - (n - films) : kNoFilm;
}

// Samples per pixel of each training iteration: [i] those of the passes that feed artifact i + 1.
std::vector<uint32_t> iteration_samples(const PassProgram& program) {
  std::vector<uint32_t> spp;
  for (const PassSpec& p : program.passes) {
    if (!p.feeds || p.kind != UnitKind::Tile || *p.feeds == 0) continue;
    if (spp.size() < *p.feeds) spp.resize(*p.feeds, 0);
    spp[*p.feeds - 1] += p.samples;
  }
  return spp;
}

}  // namespace

PassProgram path_program(const PathProgramOptions& o) {
  if (std::string e = path_program_error(o); !e.empty()) throw std::invalid_argument(e);
  PassProgram program;
  program.spp = o.spp;
  program.target_error = o.target_error;
  program.adaptive_settings = o.adaptive_settings;
  const std::vector<PlannedPass> planned = planned_passes(o.spp, o.guide.has_value());
  const int iterations = planned.back().iteration + 1;  // (0 unguided)
  if (iterations > 0) {
    program.films = iteration_film(o.guide->settings, iterations - 1, iterations) + 1;
    program.combine = program.films > 1 ? FilmCombine::InverseVariance : FilmCombine::Sum;
  }
  bool adapting = false;  // (pass 0 never adapts: there is no film to plan it from)
  uint32_t begin = 0;
  for (size_t p = 0; p < planned.size(); ++p) {
    PassSpec pass;
    pass.sample_begin = begin;
    pass.samples = planned[p].samples;
    begin += pass.samples;
    pass.may_stop = o.target_error > 0 && p >= 1;
    adapting = adapting || (o.adaptive && p >= 1 &&
                            adaptive_pass(pass.sample_begin, o.spp, std::numeric_limits<uint64_t>::max(),
                                          o.adaptive_settings));
    pass.adaptive = adapting;
    bool new_guide = false;
    if (const int k = planned[p].iteration; k >= 0) {
      pass.uses = uint32_t(k);
      if (k + 1 < iterations) pass.feeds = uint32_t(k + 1);
      pass.film = iteration_film(o.guide->settings, k, iterations);
      // A pass that renders with a new guide waits for it: it is made from every pass before.
      new_guide = k > 0 && planned[p - 1].iteration != k;
    }
    pass.barrier = pass.may_stop || pass.adaptive || new_guide;
    program.passes.push_back(pass);
    if (o.light_paths) {
      PassSpec light = pass;
      light.kind = UnitKind::Paths;
      light.same_samples = true;
      light.barrier = false;
      program.passes.push_back(light);
    }
  }
  return program;
}

PassSequencer path_sequencer(const PathProgramOptions& options, const SequenceFrame& frame) {
  return path_sequencer(path_program(options), frame, options.guide);
}

PassSequencer path_sequencer(PassProgram program, const SequenceFrame& frame, const std::optional<GuidePlan>& guide) {
  std::unique_ptr<ArtifactBuilder> training;
  if (std::any_of(program.passes.begin(), program.passes.end(),
                  [](const PassSpec& p) { return p.uses.has_value() || p.feeds.has_value(); })) {
    if (!guide) throw std::invalid_argument("the passes render with guides, but there is no guide to train");
    training = std::make_unique<GuideTraining>(guide->bounds, guide->settings, iteration_samples(program));
  }
  return PassSequencer(std::move(program), frame, std::move(training));
}

}  // namespace tessera
