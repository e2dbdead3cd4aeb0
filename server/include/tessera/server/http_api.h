// The HTTP face of the coordinator (docs/api.md): routes that parse a request, call one
// Coordinator service and map its Result to a status code and a JSON body.
#pragma once

#include "tessera/server/auth.h"
#include "tessera/server/coordinator.h"

#include <cstdint>
#include <string>
#include <vector>

namespace httplib {
class Server;
}

namespace tessera::server {

class ConnectionGuard;
class ResponseRecorder;

/// A registered route: its method and its httplib pattern (a regex matched against the whole
/// path). docs/openapi.json describes exactly these (tests/farm/openapi_test.cpp).
struct Route {
  std::string method;
  std::string pattern;
};

/// Installs every /api/v1 route, /healthz, /metrics, the dashboard and the API description, the
/// checks made before any body is read (bearer token, body framing) and JSON error and exception
/// handlers; returns the routes. Bodies are read up to `max_upload_bytes` (--max-upload) plus
/// 16 MiB for a form's other fields; a longer one is discarded and refused (413). With a guard,
/// every request is reported to it (the slow-loris watch) and, at debug level, logged as an
/// "http.request" event. With a recorder, every answer is recorded (--record-responses).
std::vector<Route> install_routes(httplib::Server& http, Coordinator& coordinator, uint64_t max_upload_bytes,
                                  const AuthTokens& tokens = {}, ConnectionGuard* guard = nullptr,
                                  ResponseRecorder* recorder = nullptr);

}  // namespace tessera::server
