// tessera-server: the render farm coordinator (see docs/api.md).
#include "tessera/server/server_app.h"

#include <cstring>

int main(int argc, char** argv) {
  // The coordinator runs itself as a short-lived child to plan a submitted scene.
  if (argc == 2 && std::strcmp(argv[1], "--plan-scene") == 0) return tessera::server::run_scene_planner_main();
  tessera::server::ServerOptions options;
  if (int code = tessera::server::parse_server_args(argc, argv, options); code >= 0) return code;
  return tessera::server::run_server(options);
}
