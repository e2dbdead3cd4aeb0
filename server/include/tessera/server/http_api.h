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
class UploadSlots;

/// A registered route: its method and its httplib pattern (a regex matched against the whole
/// path). docs/openapi.json describes exactly these (tests/farm/openapi_test.cpp).
struct Route {
  std::string method;
  std::string pattern;
};

/// What the HTTP layer reports to, and asks before it reads a body; each may be null.
struct HttpHooks {
  ConnectionGuard* guard = nullptr;      // slow headers and bodies: cut off (408 for a body)
  UploadSlots* uploads = nullptr;        // concurrent uploads by kind and client address (503)
  ResponseRecorder* recorder = nullptr;  // --record-responses: every answer
};

/// Installs every /api/v1 route, /healthz, /metrics, the dashboard and the API description, the
/// checks made before any body is read (bearer token, body framing and size, upload slots;
/// http_admission.h) and JSON error and exception handlers; returns the routes. A body over its
/// kind's limit (a bundle: `max_upload_bytes`, --max-upload, plus 16 MiB for a form's other
/// fields) is refused (413) unread and its connection closed. With a guard, every request is
/// reported to it (the slow-client watch) and, at debug level, logged as an "http.request" event.
std::vector<Route> install_routes(httplib::Server& http, Coordinator& coordinator, uint64_t max_upload_bytes,
                                  const AuthTokens& tokens = {}, const HttpHooks& hooks = {});

}  // namespace tessera::server
