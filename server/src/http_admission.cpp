#include "http_admission.h"

#include "connection_guard.h"
#include "http_helpers.h"
#include "upload_slots.h"

#include <httplib.h>

#include <optional>
#include <regex>

namespace tessera::server {

using nlohmann::json;

namespace {

// cpp-httplib 0.11 bounds a body by its Content-Length only: a chunked body would be read into
// memory without limit. No client of the farm sends one, so it is refused before it is read.
// Each kind of body has its own limit, named in the 413: a bundle (scenes, jobs) --max-upload, a
// result what its unit's sums can take (Coordinator::result_limit), any other body (a small JSON
// message) 1 MiB, so that a heartbeat of 50 MB is refused unread.
constexpr uint64_t kMaxMessageBytes = uint64_t(1) << 20;

// Answered before the body is read, then the connection is closed (ConnectionGuard): the unread
// body must not be taken for a next request.
void refuse(const Admission& a, const httplib::Request& req, httplib::Response& res, int status, const std::string& error,
            const std::string& detail) {
  res.set_header("Connection", "close");
  send_json(res, status, json{{"error", error}, {"detail", detail}});
  if (a.guard) a.guard->close_after_answer(peer_of(req));
}

bool is_bundle_upload(const httplib::Request& req) {
  return req.method == "POST" && (req.path == "/api/v1/scenes" || req.path == "/api/v1/jobs");
}

// The worker id of a result upload's path (/api/v1/workers/ID/results), if it is one.
std::optional<uint64_t> result_upload_worker(const httplib::Request& req) {
  static const std::regex pattern(R"(/api/v1/workers/(\d{1,19})/results)");
  std::smatch m;
  if (req.method != "POST" || !std::regex_match(req.path, m, pattern)) return std::nullopt;
  return std::stoull(m[1].str());
}

std::optional<uint64_t> content_length(const httplib::Request& req) {
  if (!req.has_header("Content-Length")) return std::nullopt;
  try {
    return std::stoull(req.get_header_value("Content-Length"));
  } catch (const std::exception&) {
    return std::nullopt;  // (httplib refuses a malformed length itself)
  }
}

BodyLimit body_limit(const Admission& a, const httplib::Request& req) {
  if (is_bundle_upload(req)) return {max_body_bytes(a.max_upload_bytes), ""};
  if (std::optional<uint64_t> worker = result_upload_worker(req)) {
    uint64_t lease = 0;
    try {
      lease = req.has_param("lease") ? std::stoull(req.get_param_value("lease")) : 0;
    } catch (const std::exception&) {
    }
    return a.coordinator->result_limit(*worker, lease);
  }
  return {kMaxMessageBytes, "a JSON message"};
}

bool refused_large_body(const Admission& a, const httplib::Request& req, httplib::Response& res) {
  const std::optional<uint64_t> length = content_length(req);
  if (!length || (*length <= kMaxMessageBytes && !is_bundle_upload(req) && !result_upload_worker(req))) return false;
  const BodyLimit limit = body_limit(a, req);
  if (*length <= limit.bytes) return false;
  const std::string has = "the body has " + std::to_string(*length) + " bytes; ";
  refuse(a, req, res, 413, "payload_too_large",
         limit.what.empty() ? has + "the limit is " + body_limit_text(a.max_upload_bytes)
                            : has + limit.what + " may have at most " + std::to_string(limit.bytes));
  return true;
}

bool refused_chunked_body(const Admission& a, const httplib::Request& req, httplib::Response& res) {
  if (req.get_header_value("Transfer-Encoding").find("chunked") == std::string::npos) return false;
  refuse(a, req, res, 411, "length_required", "send the body with a Content-Length (chunked bodies are not accepted)");
  return true;
}

// An upload with a body takes a slot of its kind until it is answered (the logger frees it).
bool refused_upload_slot(const Admission& a, const httplib::Request& req, httplib::Response& res) {
  if (!a.uploads || content_length(req).value_or(0) == 0) return false;
  const bool bundle = is_bundle_upload(req);
  if (!bundle && !result_upload_worker(req)) return false;
  const Status slot = a.uploads->acquire(peer_of(req), req.remote_addr, bundle ? UploadKind::Bundle : UploadKind::Result);
  if (slot.ok()) return false;
  res.set_header("Retry-After", "2");
  refuse(a, req, res, http_status(slot.code), slot.error, slot.detail);
  return true;
}

bool refused(const Admission& a, const httplib::Request& req, httplib::Response& res) {
  // The answer is the same for a missing and a wrong token.
  if (!authorized(a.tokens, required_access(req.method, req.path), req.get_header_value("Authorization"))) {
    res.set_header("WWW-Authenticate", "Bearer");
    refuse(a, req, res, 401, "unauthorized", "a valid bearer token is required");
    return true;
  }
  return refused_chunked_body(a, req, res) || refused_large_body(a, req, res) || refused_upload_slot(a, req, res);
}

// Works around two cpp-httplib 0.11 habits, before it reads the body:
// - a POST without Content-Length (curl -X POST URL) is read until the connection closes, i.e.
//   until the read timeout, then refused with 400; RFC 9112 says such a request has no body.
// - a body typed application/x-www-form-urlencoded (curl --data-binary's default) is parsed as a
//   form and refused with 413 past 8 KB; the API takes no forms, so it is kept as plain bytes.
// The request object is httplib's own, non-const one; only the handler's view of it is const.
void normalise_body_headers(httplib::Request& req) {
  const bool may_have_body = req.method == "POST" || req.method == "PUT" || req.method == "PATCH" || req.method == "DELETE";
  if (may_have_body && !req.has_header("Content-Length") && !req.has_header("Transfer-Encoding"))
    req.set_header("Content-Length", "0");
  if (req.get_header_value("Content-Type").rfind("application/x-www-form-urlencoded", 0) == 0) {
    req.headers.erase("Content-Type");
    req.set_header("Content-Type", "application/octet-stream");
  }
}

}  // namespace

uint64_t max_body_bytes(uint64_t max_upload_bytes) {
  const uint64_t form = uint64_t(16) << 20;
  return max_upload_bytes > UINT64_MAX - form ? UINT64_MAX : max_upload_bytes + form;
}

std::string body_limit_text(uint64_t max_upload_bytes) {
  return std::to_string(max_body_bytes(max_upload_bytes)) + " bytes (tessera-server --max-upload " +
         std::to_string(max_upload_bytes) + " + 16 MiB for a form's other fields)";
}

void install_admission(httplib::Server& http, const Admission& a) {
  // With `Expect: 100-continue`, httplib asks this before it answers 100 and before the
  // pre-routing handler; a refusal here is the whole answer. Asked again from the pre-routing
  // handler, an upload keeps the slot it took here.
  http.set_expect_100_continue_handler([a](const httplib::Request& req, httplib::Response& res) {
    if (a.guard) a.guard->request_started(peer_of(req));
    return refused(a, req, res) ? res.status : 100;
  });
  http.set_pre_routing_handler([a](const httplib::Request& req, httplib::Response& res) {
    if (a.guard) a.guard->request_started(peer_of(req));
    if (refused(a, req, res)) return httplib::Server::HandlerResponse::Handled;
    normalise_body_headers(const_cast<httplib::Request&>(req));
    if (a.guard) a.guard->body_expected(peer_of(req), content_length(req).value_or(0));
    return httplib::Server::HandlerResponse::Unhandled;
  });
}

}  // namespace tessera::server
