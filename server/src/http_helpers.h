// What every route handler shares: the JSON answers (a service's Result mapped to a status code
// and a body), reading ids, numbers and JSON bodies from a request, and the Router that registers a
// route with httplib and keeps its list (docs/openapi.json describes exactly those).
#pragma once

#include "tessera/server/coordinator.h"
#include "tessera/server/http_api.h"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <vector>

namespace tessera::server {

/// Indented for people reading curl output; `compact` for the workers' hot path (leases).
void send_json(httplib::Response& res, int status, const nlohmann::json& body, bool compact = false);
void send_error(httplib::Response& res, const Status& s);
/// {"ok": true}, or the error.
void send(httplib::Response& res, const Status& s, int ok_status = 200);

/// A service's answer as JSON: the farm's types' to_json (farm/protocol.h, job_status.h, farm_status.h).
template <class T>
void send(httplib::Response& res, const Result<T>& r, int ok_status = 200, bool compact = false) {
  if (!r.ok()) return send_error(res, r.status);
  send_json(res, ok_status, to_json(r.value), compact);
}

/// A list answered as {"<key>": [...]}.
template <class T>
void send_list(httplib::Response& res, const char* key, const Result<std::vector<T>>& r) {
  if (!r.ok()) return send_error(res, r.status);
  nlohmann::json list = nlohmann::json::array();
  for (const T& item : r.value) list.push_back(to_json(item));
  send_json(res, 200, nlohmann::json{{key, list}});
}

/// A JSON body (an empty body is {}, for POSTs that need nothing); false with a 400 sent.
bool parse_body(const httplib::Request& req, httplib::Response& res, nlohmann::json& out);
/// Path parameter `group` as an id; false with a 400 sent.
bool parse_id(const httplib::Request& req, size_t group, uint64_t& id, httplib::Response& res);
/// Query parameter `name` as a number, `def` when absent or not one.
double query_number(const httplib::Request& req, const char* name, double def);
/// A bundle, sent as the raw body (curl --data-binary) or as the multipart field "bundle".
std::string bundle_of(const httplib::Request& req);

/// "address:port" of the request's connection, as the connection guard names peers.
std::string peer_of(const httplib::Request& req);

/// Registers routes with httplib and keeps their list. With a connection guard, each handler first
/// tells it that the request's body is in (a handler that reads the body itself: once it has), so
/// that the time a handler takes is never taken for a body that stopped arriving.
class Router {
 public:
  explicit Router(httplib::Server& http, ConnectionGuard* guard = nullptr) : http_(http), guard_(guard) {}
  void get(const char* pattern, httplib::Server::Handler h) { add("GET", pattern), http_.Get(pattern, watched(std::move(h))); }
  void post(const char* pattern, httplib::Server::Handler h) { add("POST", pattern), http_.Post(pattern, watched(std::move(h))); }
  /// A POST whose handler reads the body itself (as it arrives).
  void post(const char* pattern, httplib::Server::HandlerWithContentReader h) {
    add("POST", pattern), http_.Post(pattern, watched(std::move(h)));
  }
  void patch(const char* pattern, httplib::Server::Handler h) { add("PATCH", pattern), http_.Patch(pattern, watched(std::move(h))); }
  void del(const char* pattern, httplib::Server::Handler h) { add("DELETE", pattern), http_.Delete(pattern, watched(std::move(h))); }
  void add(const std::vector<Route>& more) { routes_.insert(routes_.end(), more.begin(), more.end()); }
  httplib::Server& http() { return http_; }
  std::vector<Route> take() { return std::move(routes_); }

 private:
  void add(const char* method, const char* pattern) { routes_.push_back({method, pattern}); }
  httplib::Server::Handler watched(httplib::Server::Handler h) const;
  httplib::Server::HandlerWithContentReader watched(httplib::Server::HandlerWithContentReader h) const;
  httplib::Server& http_;
  ConnectionGuard* guard_;
  std::vector<Route> routes_;
};

// The routes, one resource a file.
/// /healthz, /metrics, the dashboard and the API description.
void add_operation_routes(Router& r, Coordinator& c);
/// Scene bundles and the artifacts jobs render with (/api/v1/scenes, /api/v1/guides).
void add_scene_routes(Router& r, Coordinator& c);
void add_job_routes(Router& r, Coordinator& c);
void add_worker_routes(Router& r, Coordinator& c);

}  // namespace tessera::server
