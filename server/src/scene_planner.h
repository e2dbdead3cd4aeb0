// A job's plan (film, spp, files) from its scene, as the coordinator learns it at submission. The
// full load (meshes, textures, the BVH) catches broken files before a job is accepted, but the
// coordinator never renders: with a planner program it runs in a short-lived child process, so
// the hundreds of MB a large scene takes go back to the system when the child exits instead of
// staying in the coordinator's heap.
#pragma once

#include "tessera/farm/job_scene.h"
#include "tessera/server/status.h"

#include <cstdio>
#include <string>

namespace tessera::server {

struct PlanRequest {
  std::string bundle_dir;   // the unpacked bundle
  std::string scene_file;   // the XML inside it
  JobSettings settings;
};

/// Loads and plans in this process. Errors: 422 scene_unsupported / scene_load_failed with the
/// loader's message (paths inside the bundle).
Result<JobPlan> plan_scene_here(const PlanRequest& request);

/// Runs `program --plan-scene` (tessera-server itself) as a child: the request as JSON on its
/// stdin, the answer as JSON on its stdout. A child that crashes is a 422 naming the signal.
Result<JobPlan> plan_scene_in_child(const std::string& program, const PlanRequest& request);

/// The child's side: reads a request from `in`, writes the answer to `out`; the exit code.
int run_scene_planner(std::FILE* in, std::FILE* out);

}  // namespace tessera::server
