#include "tessera/server/http_api.h"

#include "connection_guard.h"
#include "event_log.h"
#include "http_helpers.h"
#include "response_recorder.h"

#include <httplib.h>
#include <spdlog/spdlog.h>

#include <optional>
#include <regex>

namespace tessera::server {

using nlohmann::json;

namespace {

// The largest body read: a bundle of --max-upload bytes plus room for a form's other fields.
uint64_t max_body_bytes(uint64_t max_upload_bytes) {
  const uint64_t form = uint64_t(16) << 20;
  return max_upload_bytes > UINT64_MAX - form ? UINT64_MAX : max_upload_bytes + form;
}

// For refusals before the body is read: the unread body must not be taken for a next request.
void refuse_and_close(httplib::Response& res, int status, const std::string& error, const std::string& detail) {
  res.set_header("Connection", "close");
  send_json(res, status, json{{"error", error}, {"detail", detail}});
}

std::string body_limit_text(uint64_t max_upload_bytes) {
  return std::to_string(max_body_bytes(max_upload_bytes)) + " bytes (tessera-server --max-upload " +
         std::to_string(max_upload_bytes) + " + 16 MiB for a form's other fields)";
}

// Why cpp-httplib refused a request itself (no handler ran).
std::string transport_error_detail(const httplib::Request& req, int status, uint64_t max_upload_bytes) {
  if (status == 404) return "no such endpoint: " + req.method + " " + req.path;
  // Its only 413 left is a Content-Length over set_payload_max_length (forms never reach it).
  if (status == 413)
    return "the body has " + req.get_header_value("Content-Length") + " bytes; the limit is " + body_limit_text(max_upload_bytes);
  return "the request was refused with HTTP " + std::to_string(status);
}

// cpp-httplib 0.11 bounds a body by its Content-Length only: a chunked body would be read into
// memory without limit. No client of the farm sends one, so it is refused before it is read.
// Each kind of body has its own limit, named in the 413: a bundle (scenes, jobs) --max-upload, a
// result what its unit's sums can take (Coordinator::result_limit), any other body (a small JSON
// message) 1 MiB, so that a heartbeat of 50 MB is refused unread.
constexpr uint64_t kMaxMessageBytes = uint64_t(1) << 20;

// The worker id of a result upload's path (/api/v1/workers/ID/results), if it is one.
std::optional<uint64_t> result_upload_worker(const std::string& path) {
  static const std::regex pattern(R"(/api/v1/workers/(\d{1,19})/results)");
  std::smatch m;
  if (!std::regex_match(path, m, pattern)) return std::nullopt;
  return std::stoull(m[1].str());
}

BodyLimit body_limit(const httplib::Request& req, Coordinator& c) {
  if (std::optional<uint64_t> worker = result_upload_worker(req.path)) {
    uint64_t lease = 0;
    try {
      lease = req.has_param("lease") ? std::stoull(req.get_param_value("lease")) : 0;
    } catch (const std::exception&) {
    }
    return c.result_limit(*worker, lease);
  }
  return {kMaxMessageBytes, "a JSON message"};
}

bool refused_large_message(const httplib::Request& req, httplib::Response& res, Coordinator& c) {
  const bool bundle = req.path == "/api/v1/scenes" || req.path == "/api/v1/jobs";
  if (bundle || !req.has_header("Content-Length")) return false;
  uint64_t length = 0;
  try {
    length = std::stoull(req.get_header_value("Content-Length"));
  } catch (const std::exception&) {
    return false;  // (httplib refuses a malformed length itself)
  }
  if (length <= kMaxMessageBytes && !result_upload_worker(req.path)) return false;
  const BodyLimit limit = body_limit(req, c);
  if (length <= limit.bytes) return false;
  refuse_and_close(res, 413, "payload_too_large",
                   "the body has " + std::to_string(length) + " bytes; " + limit.what + " may have at most " +
                       std::to_string(limit.bytes));
  return true;
}

bool refused_chunked_body(const httplib::Request& req, httplib::Response& res) {
  if (req.get_header_value("Transfer-Encoding").find("chunked") == std::string::npos) return false;
  refuse_and_close(res, 411, "length_required", "send the body with a Content-Length (chunked bodies are not accepted)");
  return true;
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

std::string peer(const httplib::Request& req) { return req.remote_addr + ":" + std::to_string(req.remote_port); }

// Every answer: to the slow-loris watch, to the recorder, and (debug) to the log.
void install_logger(httplib::Server& http, ConnectionGuard* guard, ResponseRecorder* recorder) {
  http.set_logger([guard, recorder](const httplib::Request& req, const httplib::Response& res) {
    if (guard) guard->request_finished(peer(req));
    if (recorder) recorder->record(req, res);
    log_event(spdlog::level::debug, "http.request",
              {{"method", req.method}, {"path", req.path}, {"status", res.status}, {"peer", peer(req)}});
  });
}

// Runs before the body is read: a stranger's upload is refused without being received (the
// connection is then closed). The answer is the same for a missing and a wrong token.
void install_gatekeeper(httplib::Server& http, Coordinator& c, const AuthTokens& tokens, ConnectionGuard* guard) {
  http.set_pre_routing_handler([&c, tokens, guard](const httplib::Request& req, httplib::Response& res) {
    if (guard) guard->request_started(peer(req));
    if (!authorized(tokens, required_access(req.method, req.path), req.get_header_value("Authorization"))) {
      res.set_header("WWW-Authenticate", "Bearer");
      refuse_and_close(res, 401, "unauthorized", "a valid bearer token is required");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (refused_chunked_body(req, res) || refused_large_message(req, res, c))
      return httplib::Server::HandlerResponse::Handled;
    normalise_body_headers(const_cast<httplib::Request&>(req));
    return httplib::Server::HandlerResponse::Unhandled;
  });
}

void install_error_handlers(httplib::Server& http, uint64_t max_upload_bytes) {
  // Errors httplib produces itself (no route: 404; a body over max_body_bytes, which it reads and
  // discards so that the client sees the answer: 413) get the JSON body too.
  http.set_error_handler([max_upload_bytes](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    const char* error = res.status == 404 ? "not_found" : res.status == 413 ? "payload_too_large" : "http_error";
    send_json(res, res.status, json{{"error", error}, {"detail", transport_error_detail(req, res.status, max_upload_bytes)}});
  });
  http.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown exception";
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    log_event(spdlog::level::err, "http.exception", {{"method", req.method}, {"path", req.path}, {"error", what}});
    send_json(res, 500, json{{"error", "internal"}, {"detail", what}});
  });
}

}  // namespace

std::vector<Route> install_routes(httplib::Server& http, Coordinator& c, uint64_t max_upload_bytes,
                                  const AuthTokens& tokens, ConnectionGuard* guard, ResponseRecorder* recorder) {
  http.set_payload_max_length(size_t(max_body_bytes(max_upload_bytes)));
  install_logger(http, guard, recorder);
  install_gatekeeper(http, c, tokens, guard);
  Router r(http);
  add_operation_routes(r, c);
  add_scene_routes(r, c);
  add_job_routes(r, c);
  add_worker_routes(r, c);
  install_error_handlers(http, max_upload_bytes);
  return r.take();
}

}  // namespace tessera::server
