// The HTTP face of the coordinator (docs/api.md): routes that parse a request, call one
// Coordinator service and map its Result to a status code and a JSON body.
#pragma once

#include "tessera/server/auth.h"
#include "tessera/server/coordinator.h"

namespace httplib {
class Server;
}

namespace tessera::server {

class ConnectionGuard;

/// Installs every /api/v1 route, /healthz, the bearer-token check (before any body is read) and
/// JSON error and exception handlers. With a guard, every request is reported to it (the
/// slow-loris watch) and, at debug level, logged as an "http.request" event.
void install_routes(httplib::Server& http, Coordinator& coordinator, const AuthTokens& tokens = {},
                    ConnectionGuard* guard = nullptr);

}  // namespace tessera::server
