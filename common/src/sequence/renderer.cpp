#include "tessera/sequence/renderer.h"

#include "tessera/core/check.h"
#include "tessera/render/integrator.h"
#include "tessera/sequence/guide_training.h"
#include "tessera/sequence/local_driver.h"
#include "tessera/sequence/path_program.h"
#include "tessera/sequence/photon_program.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

namespace tessera {

namespace {

// The path tracer's units: tiles, guided by the artifact (SD-tree) the pass renders with.
class PathUnits final : public UnitRenderer {
 public:
  PathUnits(const Scene& scene, uint32_t seed, bool aovs, GuideTraining* guide)
      : scene_(scene), integrator_(make_integrator(scene.integrator)), seed_(seed), aovs_(aovs), guide_(guide) {}

  void prepare(PassSequencer& sequencer, uint32_t pass) override {
    // A training pass's units record straight into the next tree's sums (thread-safe records).
    if (guide_ && sequencer.pass(pass).feeds) (void)guide_->recorder();
  }

  void render(const PassSequencer& sequencer, const UnitWork& work, UnitResult& result) override {
    if (work.kind == UnitKind::Paths) {
      render_light_unit(scene_, work.path_begin, work.path_end, seed_, result.splats);
      return;
    }
    std::optional<PathGuide> guide;
    if (work.uses) {
      const auto& tree = static_cast<const GuideArtifact*>(sequencer.artifact(*work.uses))->tree();
      guide = PathGuide::of(&tree, work.feeds ? &guide_->recorder() : nullptr, *work.uses > 0, work.feeds.has_value(),
                            guide_->settings());
    }
    const PassSamples samples = work.samples ? *work.samples : PassSamples::uniform(work.rect, work.sample_begin, work.sample_end);
    render_tile(scene_, *integrator_, work.rect, samples, seed_, result.tile, guide ? &*guide : nullptr, aovs_);
  }

 private:
  const Scene& scene_;
  std::unique_ptr<Integrator> integrator_;
  uint32_t seed_;
  bool aovs_;
  GuideTraining* guide_;
};

// sppm's and vcm's units (photon_program.h).
class LightVertexUnits final : public UnitRenderer {
 public:
  LightVertexUnits(const Scene& scene, uint32_t seed) : scene_(scene), seed_(seed) {}
  void render(const PassSequencer& sequencer, const UnitWork& work, UnitResult& result) override {
    render_light_vertex_unit(scene_, work.uses ? sequencer.artifact(*work.uses) : nullptr, work, seed_, result);
  }

 private:
  const Scene& scene_;
  uint32_t seed_;
};

}  // namespace

std::string technique_settings_error(IntegratorType type, bool aovs, double target_error, bool adaptive, bool guiding) {
  if (aovs && (is_bidirectional(type) || uses_light_vertex_passes(type)))
    return "AOVs and denoising need the path tracer (integrator path or volpath): the " + std::string(integrator_name(type)) +
           " integrator's image is not the mean of a pixel's own samples";
  if (!uses_light_vertex_passes(type)) return {};
  const char* what = target_error > 0 ? "a target error" : adaptive ? "adaptive sampling" : guiding ? "path guiding" : nullptr;
  if (!what) return {};
  return std::string("the ") + integrator_name(type) +
         " integrator's passes refine an estimate from the light of their own pass, which a pixel's samples do not "
         "show the noise of: " + what + " needs the path tracer (integrator path or volpath)";
}

Film render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress, RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  TESSERA_CHECK(settings.spp >= 0 && settings.tile_size > 0);
  PathProgramOptions options{uint32_t(settings.spp), settings.target_error, settings.adaptive, settings.adaptive_settings,
                             guide_plan(scene, settings.guiding, settings.guiding_settings),
                             traces_light_paths(scene.integrator)};
  if (std::string e = technique_settings_error(scene.integrator.type, settings.aovs, settings.target_error,
                                               settings.adaptive, settings.guiding.value_or(false));
      !e.empty())
    throw std::invalid_argument(e);
  const SequenceFrame frame{film_window(scene.film), scene.film.width, scene.film.height, settings.tile_size, settings.aovs};
  const bool light_vertices = uses_light_vertex_passes(scene.integrator.type);
  PassSequencer sequencer =
      light_vertices ? light_vertex_sequencer(scene, options.spp, frame) : path_sequencer(options, frame);
  auto* training = dynamic_cast<GuideTraining*>(sequencer.builder());
  std::unique_ptr<UnitRenderer> units_owned;
  if (light_vertices) units_owned = std::make_unique<LightVertexUnits>(scene, settings.seed);
  else units_owned = std::make_unique<PathUnits>(scene, settings.seed, settings.aovs, training);
  UnitRenderer& units = *units_owned;
  RenderProgress prog;
  prog.num_passes = int(sequencer.num_passes());
  prog.tiles_total = int64_t(sequencer.num_units());
  prog.spp = uint32_t(settings.spp);
  run_locally(sequencer, units, settings.threads, [&](const PassSequencer& s, uint32_t pass) {
    prog.pass = int(pass);
    prog.tiles_done = int64_t(s.done_units());
    prog.samples_done = s.spp_complete();
    prog.done_fraction = double(s.done_samples()) / double(std::max<uint64_t>(1, s.planned_samples()));
    if (progress) progress(prog);
  });
  FilmAssembler& films = sequencer.films();
  Film film = !films.allocated()                                      ? Film(scene.film, settings.aovs)
              : sequencer.program().combine == FilmCombine::InverseVariance ? films.combined_film()
                                                                          : films.take_film(films.primary_film());
  film.add_counters(films.counters());
  if (stats) {
    stats->counters = films.counters();
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats->spp_done = sequencer.stopped() ? sequencer.spp_complete() : sequencer.program().spp;
    if (training && training->latest()) {
      stats->guide_leaves = training->tree_leaves();
      stats->guide_bytes = training->tree_bytes();
      stats->guide_gain = training->predicted_gain();
      stats->guide_stepped_aside = training->stepped_aside();
    }
    stats->noise_estimate = settings.target_error > 0 ? estimate_noise(film).rel_mse : 0;
  }
  return film;
}

}  // namespace tessera
