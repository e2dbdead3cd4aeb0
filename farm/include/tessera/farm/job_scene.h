// Loading a job's scene the same way everywhere: the coordinator at submission (to fail fast and
// learn the film), each worker before rendering, and `tessera submit` before bundling. One function
// so that they can never disagree about what the settings mean. (`tessera render` loads through
// the same parse_scene_file/load_scene with the same options, timing each step itself.)
#pragma once

#include "tessera/farm/splat_result.h"

#include "tessera/farm/protocol.h"
#include "tessera/farm/tile_result.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/image/image.h"
#include "tessera/sequence/path_program.h"
#include "tessera/sequence/photon_program.h"
#include "tessera/scene/load_context.h"

#include <string>
#include <vector>

namespace tessera {

/// What the coordinator needs to know about a job's scene to cut it into work.
struct JobPlan {
  JobSettings settings;          // spp, width, height resolved from the scene where they were 0
  std::string scene_file;        // XML path inside the bundle
  std::vector<std::string> files;  // bundle-relative files the scene references, XML first
  TileRect window;               // the film's crop window
  int full_width = 0, full_height = 0;
  bool ldr = false;              // ldrfilm: PNG output uses gamma/exposure below
  float gamma = -1.f, exposure = 0.f;
  /// A guided job: the SD-tree as render() starts it (over the scene's bounds) and its settings.
  using Guide = GuidePlan;
  std::optional<Guide> guide;
  /// An sppm or vcm job whose passes feed maps: how the coordinator makes them (never from the
  /// scene, which it does not load again after a restart).
  std::optional<PointMapPlan> points;
  /// The passes the job was planned with (path_program() of path_options()): a coordinator that
  /// resumes it runs these, whatever a later build would plan for the same settings.
  PassProgram program;
};

/// The job's path-tracer options (sequence/path_program.h): the sequencer the coordinator runs
/// is the one `tessera render` runs with the same settings.
PathProgramOptions path_options(const JobPlan& plan);
/// The job's passes: its plan's program, or (a plan without one: stored before programs were kept,
/// or made by hand) the one its settings give.
PassProgram job_program(const JobPlan& plan);

struct LoadedJobScene {
  SceneDesc desc;
  LoadResult loaded;
};

/// Parses and loads `bundle_dir/scene_file` with the job's defines, size, spp, integrator and light
/// selection. Throws SceneError / UnsupportedError as load_scene does (messages name the file and
/// line inside the bundle). With `confine` (bundles from the network: coordinator, worker) every
/// file the scene opens must lie inside bundle_dir; the client loading a user's own scene folder
/// before bundling it passes false, since its references may reach above that folder.
LoadedJobScene load_job_scene(const std::string& bundle_dir, const std::string& scene_file,
                              const JobSettings& settings, bool confine = true);

/// The plan for a loaded scene (`files` made relative to bundle_dir).
JobPlan make_job_plan(const std::string& bundle_dir, const std::string& scene_file, const JobSettings& settings,
                      const LoadedJobScene& scene);

/// Sets `out` to the lease's unit (job, tile, pass, samples) with a zero film of its rectangle,
/// reusing its storage: a result about to be filled.
/// The image layers the job's EXR carries (as `tessera render --aovs/--denoise` writes them): those
/// of `aovs`, else with `denoise` every layer the denoiser reads, else none. Keeps, in `layers`,
/// only those.
void keep_job_exr_layers(const JobSettings& settings, std::vector<ImageLayer>& layers);

void begin_tile_result(const Lease& lease, TileResult& out);
/// Renders a lease's unit (what a worker does with it), timed. A guided lease needs its guide
/// (Lease::guide, decoded): a unit that trains returns its training records with the result.
TileResult render_lease(const Scene& scene, const Lease& lease, const SpatialTree* guide = nullptr);
/// Renders a lease of an sppm or vcm job (uses_light_vertex_passes of the scene's integrator) as
/// `tessera render` renders the unit (render_light_vertex_unit): a Tile lease's gather or camera
/// tile, with the per-pixel state its tile's next pass starts from; `points`: the map it renders
/// with (Lease::guide, decoded by decode_point_map), if any.
TileResult render_light_vertex_tile(const Scene& scene, const Lease& lease, const Artifact* points);
/// The same for a Paths lease: its photons' or light subpaths' records, and their splats.
SplatResult render_light_vertex_paths(const Scene& scene, const Lease& lease);
/// Renders a lease of light paths (Lease::paths) of a light-tracing integrator (render/bdpt.h):
/// the splats its paths add to the film's window. Throws std::invalid_argument for a lease that
/// is not one, or a scene whose integrator traces no light paths.
SplatResult render_paths_lease(const Scene& scene, const Lease& lease);

nlohmann::json to_json(const JobPlan& p);
[[nodiscard]] bool job_plan_from_json(const nlohmann::json& j, JobPlan& out, std::string& error);

}  // namespace tessera
