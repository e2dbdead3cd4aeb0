#include "tessera/server/http_api.h"

#include "connection_guard.h"
#include "event_log.h"

#include "dashboard.h"
#include "response_recorder.h"

#include <httplib.h>
#include <spdlog/spdlog.h>


namespace tessera::server {

using nlohmann::json;

namespace {

// Indented for people reading curl output; `compact` for the workers' hot path (leases).
void send_json(httplib::Response& res, int status, const json& body, bool compact = false) {
  res.status = status;
  res.set_content((compact ? body.dump() : body.dump(2)) + "\n", "application/json");
}

void send_error(httplib::Response& res, const Status& s) {
  send_json(res, http_status(s.code), json{{"error", s.error}, {"detail", s.detail}});
}

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
// Bundles (scenes, jobs) may be as large as --max-upload, a tile result as its largest tile; every
// other body is a small JSON message, so a heartbeat of 50 MB is refused unread.
constexpr uint64_t kMaxMessageBytes = uint64_t(1) << 20, kMaxResultBytes = uint64_t(64) << 20;

bool refused_large_message(const httplib::Request& req, httplib::Response& res) {
  const bool bundle = req.path == "/api/v1/scenes" || req.path == "/api/v1/jobs";
  if (bundle || !req.has_header("Content-Length")) return false;
  const bool result = req.path.size() > 8 && req.path.compare(req.path.size() - 8, 8, "/results") == 0;
  const uint64_t limit = result ? kMaxResultBytes : kMaxMessageBytes;
  uint64_t length = 0;
  try {
    length = std::stoull(req.get_header_value("Content-Length"));
  } catch (const std::exception&) {
    return false;  // (httplib refuses a malformed length itself)
  }
  if (length <= limit) return false;
  refuse_and_close(res, 413, "payload_too_large",
                   "the body has " + std::to_string(length) + " bytes; " + (result ? "a tile result" : "this message") +
                       " may have at most " + std::to_string(limit));
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

// A service's answer as JSON: the farm's types' to_json (farm/protocol.h, job_status.h, farm_status.h).
template <class T>
void send(httplib::Response& res, const Result<T>& r, int ok_status = 200, bool compact = false) {
  if (!r.ok()) return send_error(res, r.status);
  send_json(res, ok_status, to_json(r.value), compact);
}

// A list answered as {"<key>": [...]}.
template <class T>
void send_list(httplib::Response& res, const char* key, const Result<std::vector<T>>& r) {
  if (!r.ok()) return send_error(res, r.status);
  json list = json::array();
  for (const T& item : r.value) list.push_back(to_json(item));
  send_json(res, 200, json{{key, list}});
}

void send(httplib::Response& res, const Status& s, int ok_status = 200) {
  if (!s.ok()) return send_error(res, s);
  send_json(res, ok_status, json{{"ok", true}});
}

// A JSON body; an empty body is {} (for POSTs that need nothing).
bool parse_body(const httplib::Request& req, httplib::Response& res, json& out) {
  if (req.body.empty()) {
    out = json::object();
    return true;
  }
  out = json::parse(req.body, nullptr, false);
  if (out.is_discarded()) {
    send_error(res, make_error(Code::BadRequest, "bad_json", "the request body is not valid JSON"));
    return false;
  }
  return true;
}

bool parse_id(const httplib::Request& req, size_t group, uint64_t& id, httplib::Response& res) {
  try {
    id = std::stoull(req.matches[group].str());
    return true;
  } catch (const std::exception&) {
    send_error(res, make_error(Code::BadRequest, "bad_id", "'" + req.matches[group].str() + "' is not an id"));
    return false;
  }
}

double query_number(const httplib::Request& req, const char* name, double def) {
  if (!req.has_param(name)) return def;
  try {
    return std::stod(req.get_param_value(name));
  } catch (const std::exception&) {
    return def;
  }
}

// A bundle arrives as a raw body (curl --data-binary) or as the multipart field "bundle".
std::string bundle_of(const httplib::Request& req) {
  if (req.is_multipart_form_data()) return req.has_file("bundle") ? req.get_file_value("bundle").content : "";
  return req.body;
}

// Registers routes with httplib and keeps their list.
class Router {
 public:
  explicit Router(httplib::Server& http) : http_(http) {}
  void get(const char* pattern, httplib::Server::Handler h) { add("GET", pattern), http_.Get(pattern, std::move(h)); }
  void post(const char* pattern, httplib::Server::Handler h) { add("POST", pattern), http_.Post(pattern, std::move(h)); }
  void patch(const char* pattern, httplib::Server::Handler h) { add("PATCH", pattern), http_.Patch(pattern, std::move(h)); }
  void del(const char* pattern, httplib::Server::Handler h) { add("DELETE", pattern), http_.Delete(pattern, std::move(h)); }
  void add(const std::vector<Route>& more) { routes_.insert(routes_.end(), more.begin(), more.end()); }
  std::vector<Route> take() { return std::move(routes_); }

 private:
  void add(const char* method, const char* pattern) { routes_.push_back({method, pattern}); }
  httplib::Server& http_;
  std::vector<Route> routes_;
};

}  // namespace

std::vector<Route> install_routes(httplib::Server& http, Coordinator& c, uint64_t max_upload_bytes,
                                  const AuthTokens& tokens, ConnectionGuard* guard, ResponseRecorder* recorder) {
  http.set_payload_max_length(size_t(max_body_bytes(max_upload_bytes)));
  auto peer = [](const httplib::Request& req) { return req.remote_addr + ":" + std::to_string(req.remote_port); };
  http.set_logger([guard, recorder, peer](const httplib::Request& req, const httplib::Response& res) {
    if (guard) guard->request_finished(peer(req));
    if (recorder) recorder->record(req, res);
    log_event(spdlog::level::debug, "http.request",
              {{"method", req.method}, {"path", req.path}, {"status", res.status}, {"peer", peer(req)}});
  });
  // Runs before the body is read: a stranger's upload is refused without being received (the
  // connection is then closed). The answer is the same for a missing and a wrong token.
  http.set_pre_routing_handler([tokens, guard, peer](const httplib::Request& req, httplib::Response& res) {
    if (guard) guard->request_started(peer(req));
    if (!authorized(tokens, required_access(req.method, req.path), req.get_header_value("Authorization"))) {
      res.set_header("WWW-Authenticate", "Bearer");
      refuse_and_close(res, 401, "unauthorized", "a valid bearer token is required");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (refused_chunked_body(req, res) || refused_large_message(req, res)) return httplib::Server::HandlerResponse::Handled;
    normalise_body_headers(const_cast<httplib::Request&>(req));
    return httplib::Server::HandlerResponse::Unhandled;
  });

  Router r(http);
  r.get("/healthz", [&c](const httplib::Request&, httplib::Response& res) { send_json(res, 200, to_json(c.health())); });
  r.add(install_dashboard(http));

  r.get("/metrics", [&c](const httplib::Request&, httplib::Response& res) {
    res.set_content(c.metrics(), "text/plain; version=0.0.4");
  });

  r.post("/api/v1/scenes", [&c](const httplib::Request& req, httplib::Response& res) {
    std::string bundle = bundle_of(req);
    if (bundle.empty())
      return send_error(res, make_error(Code::BadRequest, "no_bundle", "send the bundle as the body or field 'bundle'"));
    send(res, c.upload_scene(bundle), 201);
  });
  r.get(R"(/api/v1/scenes/([0-9a-f]{64}))", [&c](const httplib::Request& req, httplib::Response& res) {
    Result<std::string> bundle = c.scene_bundle(req.matches[1].str());
    if (!bundle.ok()) return send_error(res, bundle.status);
    res.set_content(bundle.value, "application/octet-stream");
  });

  r.get(R"(/api/v1/guides/([0-9a-f]{64}))", [&c](const httplib::Request& req, httplib::Response& res) {
    Result<std::string> guide = c.guide(req.matches[1].str());
    if (!guide.ok()) return send_error(res, guide.status);
    res.set_content(guide.value, "application/octet-stream");
  });

  r.post("/api/v1/jobs", [&c](const httplib::Request& req, httplib::Response& res) {
    json settings;
    std::string bundle;
    if (req.is_multipart_form_data()) {
      settings = req.has_file("settings") ? json::parse(req.get_file_value("settings").content, nullptr, false)
                                          : json::object();
      if (settings.is_discarded())
        return send_error(res, make_error(Code::BadRequest, "bad_json", "field 'settings' is not valid JSON"));
      bundle = bundle_of(req);
    } else if (!parse_body(req, res, settings)) {
      return;
    }
    JobRequest request;
    std::string error;
    if (!job_request_from_json(settings, request, error, /*require_scene=*/bundle.empty()))
      return send_error(res, make_error(Code::BadRequest, "bad_settings", error));
    send(res, c.submit_job(request, bundle), 201);
  });
  r.get("/api/v1/jobs", [&c](const httplib::Request&, httplib::Response& res) { send_list(res, "jobs", c.list_jobs()); });
  r.get(R"(/api/v1/jobs/(\d+))", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (parse_id(req, 1, id, res)) send(res, c.job_status(id));
  });
  r.get(R"(/api/v1/jobs/(\d+)/image)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (!parse_id(req, 1, id, res)) return;
    const bool denoised = req.has_param("denoised") && req.get_param_value("denoised") != "0";
    Result<ImageBytes> image =
        c.job_image(id, req.has_param("format") ? req.get_param_value("format") : "exr", denoised);
    if (!image.ok()) return send_error(res, image.status);
    res.set_content(image.value.bytes, image.value.content_type.c_str());
  });
  r.del(R"(/api/v1/jobs/(\d+))", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (parse_id(req, 1, id, res)) send(res, c.cancel_job(id));
  });

  r.patch(R"(/api/v1/jobs/(\d+))", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    json body;
    if (!parse_id(req, 1, id, res) || !parse_body(req, res, body)) return;
    if (!body.is_object() || body.size() != 1 || !body.contains("priority") || !body["priority"].is_number_integer())
      return send_error(res, make_error(Code::BadRequest, "bad_request", "send {\"priority\": N}"));
    send(res, c.set_priority(id, body["priority"].get<int>()));
  });
  r.post(R"(/api/v1/jobs/(\d+)/retry)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (parse_id(req, 1, id, res)) send(res, c.retry_job(id));
  });

  r.post(R"(/api/v1/workers/(\d+)/drain)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (parse_id(req, 1, id, res)) send(res, c.drain_worker(id));
  });
  r.post("/api/v1/workers", [&c](const httplib::Request& req, httplib::Response& res) {
    json body;
    if (!parse_body(req, res, body)) return;
    WorkerHello hello;
    std::string error;
    if (!worker_hello_from_json(body, hello, error))
      return send_error(res, make_error(Code::BadRequest, "bad_registration", error));
    send(res, c.register_worker(hello), 201);
  });
  r.get("/api/v1/workers", [&c](const httplib::Request&, httplib::Response& res) {
    send_list(res, "workers", c.list_workers());
  });
  r.post(R"(/api/v1/workers/(\d+)/lease)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (!parse_id(req, 1, id, res)) return;
    Result<std::optional<Lease>> lease = c.lease(id, query_number(req, "wait", 0));
    if (!lease.ok()) return send_error(res, lease.status);
    if (!lease.value) {
      res.status = 204;
      res.set_header("Retry-After", "1");
      return;
    }
    send_json(res, 200, to_json(*lease.value), /*compact=*/true);
  });
  r.post(R"(/api/v1/workers/(\d+)/heartbeat)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    json body;
    if (!parse_id(req, 1, id, res) || !parse_body(req, res, body)) return;
    Heartbeat heartbeat;
    std::string error;
    if (!heartbeat_from_json(body, heartbeat, error))
      return send_error(res, make_error(Code::BadRequest, "bad_heartbeat", error));
    Result<std::vector<uint64_t>> drop = c.heartbeat(id, heartbeat);
    if (!drop.ok()) return send_error(res, drop.status);
    send_json(res, 200, json{{"drop", drop.value}});
  });
  r.post(R"(/api/v1/workers/(\d+)/results)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    if (!parse_id(req, 1, id, res)) return;
    // (Compact, as the lease's answer: a worker's hot path, read by programs.)
    send(res, c.upload_result(id, uint64_t(query_number(req, "lease", 0)), req.body, query_number(req, "next", 0) != 0),
         200, /*compact=*/true);
  });
  r.post(R"(/api/v1/workers/(\d+)/leases/(\d+)/fail)", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id, lease;
    json body;
    if (!parse_id(req, 1, id, res) || !parse_id(req, 2, lease, res) || !parse_body(req, res, body)) return;
    const bool has_reason = body.is_object() && body.contains("error") && body["error"].is_string();
    send(res, c.fail_lease(id, lease, has_reason ? body["error"].get<std::string>() : "unspecified"));
  });
  r.del(R"(/api/v1/workers/(\d+))", [&c](const httplib::Request& req, httplib::Response& res) {
    uint64_t id;
    json body;
    if (parse_id(req, 1, id, res) && parse_body(req, res, body)) send(res, c.sign_off(id));
  });

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
  return r.take();
}

}  // namespace tessera::server
