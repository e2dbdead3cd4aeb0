// `tessera bench rays`: geometry from OBJ files/folders (rayfile.md soup order) or a scene file.
#include "tessera/cli/command_line.h"
#include "tessera/cli/commands.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <iostream>
#include <memory>

namespace tessera::cli {
namespace {

bool is_scene_file(const std::string& path) {
  return path.size() > 4 && path.compare(path.size() - 4, 4, ".xml") == 0;
}

}  // namespace

int run_bench_rays(const BenchRaysOptions& options) {
  try {
    if (options.geometry.size() == 1 && is_scene_file(options.geometry[0])) {
      int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
      tbb::task_arena arena(threads);
      BenchRaysResult result;
      arena.execute([&] {
        LoadOptions load;
        load.allow_unsupported = true;  // only geometry matters here
        LoadResult loaded = load_scene(parse_scene_file(options.geometry[0]), load);
        std::cout << "build triangles=" << loaded.scene->num_triangles() << " threads=" << threads
                  << " seconds=" << loaded.scene->bvh_build_seconds() << "\n";
        result = bench_rays_on(loaded.scene->accel(), options, std::cout);
      });
      (void)result;
      return 0;
    }
    BenchRaysResult result = bench_rays(options, std::cout);
    (void)result;
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}

std::vector<Command> add_bench_commands(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks");
  bench->require_subcommand(1);
  auto rays = std::make_shared<BenchRaysOptions>();
  CLI::App* br = bench->add_subcommand("rays", "Trace a ray file (../shared/docs/rayfile.md) and report Mrays/s");
  br->add_option("geometry", rays->geometry, "Scene .xml, or OBJ files/folders")->required();
  br->add_option("--rays", rays->rays, "Ray file")->required()->check(CLI::ExistingFile);
  br->add_option("--hits", rays->hits_out, "Write the hit file here");
  br->add_option("--compare", rays->compare, "Reference hit file to check agreement against")->check(CLI::ExistingFile);
  br->add_option("--threads", rays->threads, "Threads (default: all cores)")->check(CLI::NonNegativeNumber);
  br->add_option("--repeat", rays->repeat, "Trace each set this often and report the median (default 1)")
      ->check(CLI::Range(1, 100));
  return {Command{br, [rays] { return run_bench_rays(*rays); }}, add_convergence_command(*bench)};
}

}  // namespace tessera::cli
