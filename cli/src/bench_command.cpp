// `tessera bench rays`: geometry from OBJ files/folders (rayfile.md soup order) or a scene file.
#include "tessera/cli/commands.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <iostream>

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

}  // namespace tessera::cli
