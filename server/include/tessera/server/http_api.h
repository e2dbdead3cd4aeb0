// The HTTP face of the coordinator (docs/api.md): routes that parse a request, call one
// Coordinator service and map its Result to a status code and a JSON body.
#pragma once

#include "tessera/server/auth.h"
#include "tessera/server/coordinator.h"

namespace httplib {
class Server;
}

namespace tessera::server {

/// Installs every /api/v1 route, /healthz, the bearer-token check (before any body is read) and
/// JSON error and exception handlers.
void install_routes(httplib::Server& http, Coordinator& coordinator, const AuthTokens& tokens = {});

}  // namespace tessera::server
