// The checks made once a request's headers are in and before any of its body is read: the bearer
// token (401), the body's framing (411), its size against its kind's limit (413) and, for an
// upload, a slot (503, upload_slots.h). They run from httplib's pre-routing handler and from its
// `Expect: 100-continue` handler, so that a client waiting for 100 Continue is refused before it
// sends a byte. A refused request is answered and its connection closed: its body is never read.
#pragma once

#include "tessera/server/auth.h"
#include "tessera/server/coordinator.h"

#include <cstdint>
#include <string>

namespace httplib {
class Server;
}

namespace tessera::server {

class ConnectionGuard;
class UploadSlots;

struct Admission {
  Coordinator* coordinator = nullptr;
  AuthTokens tokens;
  uint64_t max_upload_bytes = 0;     // --max-upload
  ConnectionGuard* guard = nullptr;  // may be null (in-process tests)
  UploadSlots* uploads = nullptr;    // may be null: no slots
};

void install_admission(httplib::Server& http, const Admission& admission);

/// The largest bundle body read: --max-upload bytes plus room for a form's other fields.
uint64_t max_body_bytes(uint64_t max_upload_bytes);
/// That limit as a 413 names it.
std::string body_limit_text(uint64_t max_upload_bytes);

}  // namespace tessera::server
