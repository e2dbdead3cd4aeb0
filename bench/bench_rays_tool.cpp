// Stand-alone driver for the ray benchmark (the `tessera bench rays` command calls the same
// library function). Prints figures; asserts nothing.
#include "tessera/scene/error.h"
#include "tessera/tools/bench_rays.h"

#include <CLI/CLI.hpp>

#include <iostream>

int main(int argc, char** argv) {
  tessera::BenchRaysOptions opt;
  CLI::App app{"Trace a ray file (../shared/docs/rayfile.md) against an OBJ triangle soup"};
  app.add_option("geometry", opt.geometry, "OBJ files or folders (folders: every *.obj, sorted)")->required();
  app.add_option("--rays", opt.rays, "ray file")->required();
  app.add_option("--hits-out", opt.hits_out, "write the answers to this hit file");
  app.add_option("--compare", opt.compare, "reference hit file to compare against");
  app.add_option("--threads", opt.threads, "threads (0: all)");
  app.add_option("--repeat", opt.repeat, "trace each set this often; report the median");
  CLI11_PARSE(app, argc, argv);
  try {
    tessera::bench_rays(opt, std::cout);
  } catch (const std::exception& e) {
    std::cerr << "bench_rays_tool: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
