// The HTTP face of the coordinator (docs/api.md): routes that parse a request, call one
// Coordinator service and map its Result to a status code and a JSON body.
#pragma once

#include "tessera/server/auth.h"
#include "tessera/server/coordinator.h"

#include <cstdint>

namespace httplib {
class Server;
}

namespace tessera::server {

class ConnectionGuard;

/// Installs every /api/v1 route, /healthz, the checks made before any body is read (bearer
/// token, body framing) and JSON error and exception handlers. Bodies are read up to
/// `max_upload_bytes` (--max-upload) plus 16 MiB for a form's other fields; a longer one is
/// discarded and refused (413). With a guard, every request is reported to it (the slow-loris
/// watch) and, at debug level, logged as an "http.request" event.
void install_routes(httplib::Server& http, Coordinator& coordinator, uint64_t max_upload_bytes,
                    const AuthTokens& tokens = {}, ConnectionGuard* guard = nullptr);

}  // namespace tessera::server
