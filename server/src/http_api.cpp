#include "tessera/server/http_api.h"

#include "connection_guard.h"
#include "event_log.h"
#include "http_admission.h"
#include "http_helpers.h"
#include "response_recorder.h"
#include "upload_slots.h"

#include <httplib.h>
#include <spdlog/spdlog.h>

namespace tessera::server {

using nlohmann::json;

namespace {

// Why cpp-httplib refused a request itself (no handler ran).
std::string transport_error_detail(const httplib::Request& req, int status, uint64_t max_upload_bytes) {
  if (status == 404) return "no such endpoint: " + req.method + " " + req.path;
  // Its only 413 left is a Content-Length over set_payload_max_length (forms never reach it).
  if (status == 413)
    return "the body has " + req.get_header_value("Content-Length") + " bytes; the limit is " + body_limit_text(max_upload_bytes);
  return "the request was refused with HTTP " + std::to_string(status);
}

// Every answer: to the slow-client watch, to the upload slots, to the recorder, and (debug) to the log.
void install_logger(httplib::Server& http, const HttpHooks& hooks) {
  http.set_logger([hooks](const httplib::Request& req, const httplib::Response& res) {
    const std::string peer = peer_of(req);
    if (hooks.uploads) hooks.uploads->release(peer);
    if (hooks.guard) hooks.guard->request_finished(peer);
    if (hooks.recorder) hooks.recorder->record(req, res);
    log_event(spdlog::level::debug, "http.request",
              {{"method", req.method}, {"path", req.path}, {"status", res.status}, {"peer", peer}});
  });
}

void install_error_handlers(httplib::Server& http, uint64_t max_upload_bytes, ConnectionGuard* guard) {
  // Errors httplib produces itself (no route: 404; a body that ended early: 400) get the JSON body
  // too. A body the connection guard cut off for arriving too slowly is a 408 naming the limit,
  // whatever the reading code made of its end (httplib's 400, a handler's incomplete_body).
  http.set_error_handler([max_upload_bytes, guard](const httplib::Request& req, httplib::Response& res) {
    const std::string too_slow = guard ? guard->body_timeout(peer_of(req)) : std::string();
    if (!too_slow.empty()) {
      res.set_header("Connection", "close");
      return send_json(res, 408, json{{"error", "body_too_slow"}, {"detail", too_slow}});
    }
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
                                  const AuthTokens& tokens, const HttpHooks& hooks) {
  http.set_payload_max_length(size_t(max_body_bytes(max_upload_bytes)));
  install_logger(http, hooks);
  install_admission(http, Admission{&c, tokens, max_upload_bytes, hooks.guard, hooks.uploads});
  Router r(http, hooks.guard);
  add_operation_routes(r, c);
  add_scene_routes(r, c);
  add_job_routes(r, c);
  add_worker_routes(r, c);
  install_error_handlers(http, max_upload_bytes, hooks.guard);
  return r.take();
}

}  // namespace tessera::server
