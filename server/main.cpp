// tessera-server: the render farm coordinator (see docs/api.md).
#include "tessera/server/server_app.h"

int main(int argc, char** argv) {
  tessera::server::ServerOptions options;
  if (int code = tessera::server::parse_server_args(argc, argv, options); code >= 0) return code;
  return tessera::server::run_server(options);
}
