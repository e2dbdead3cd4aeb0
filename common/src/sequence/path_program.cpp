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

PassProgram path_program(const PathProgramOptions& o) {
  if (std::string e = path_program_error(o); !e.empty()) throw std::invalid_argument(e);
  PassProgram program;
  program.spp = o.spp;
  program.target_error = o.target_error;
  program.adaptive_settings = o.adaptive_settings;
  const std::vector<uint32_t> schedule = pass_schedule(o.spp);
  uint32_t training = 0;  // passes that train the guide
  while (o.guide && training < schedule.size() && guiding_trains_pass(schedule, training, o.spp)) ++training;
  bool adapting = false;  // (pass 0 never adapts: there is no film to plan it from)
  uint32_t begin = 0;
  for (uint32_t p = 0; p < schedule.size(); ++p) {
    PassSpec pass;
    pass.sample_begin = begin;
    pass.samples = schedule[p];
    begin += schedule[p];
    pass.may_stop = o.target_error > 0 && p >= 1;
    adapting = adapting || (o.adaptive && p >= 1 &&
                            adaptive_pass(pass.sample_begin, o.spp, std::numeric_limits<uint64_t>::max(),
                                          o.adaptive_settings));
    pass.adaptive = adapting;
    if (training > 0) {
      const uint32_t iteration = std::min(p, training);
      if (p < training) pass.feeds = p + 1;
      if (p < training || iteration > 0) pass.uses = iteration;
      if (p < training && o.guide->settings.discard_training) pass.film = kNoFilm;
    }
    // A pass that renders with a new guide waits for it: it is made from every pass before.
    const bool new_guide = pass.uses && *pass.uses > 0 && p <= training;
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
    training = std::make_unique<GuideTraining>(guide->bounds, guide->settings);
  }
  return PassSequencer(std::move(program), frame, std::move(training));
}

}  // namespace tessera
