// Workers: registration, lease long polls, heartbeats, results, failures, sign-off and draining.
#include "http_helpers.h"
#include "upload_spool.h"

namespace tessera::server {

using nlohmann::json;

void add_worker_routes(Router& r, Coordinator& c) {
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
  r.post(R"(/api/v1/workers/(\d+)/results)",
         [&c](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
           uint64_t id;
           if (!parse_id(req, 1, id, res)) return;
           Result<std::shared_ptr<const UploadBytes>> body = read_upload(reader, c.spool_dir());
           if (!body.ok()) return send_error(res, body.status);
           // (Compact, as the lease's answer: a worker's hot path, read by programs.)
           send(res,
                c.upload_result(id, uint64_t(query_number(req, "lease", 0)), std::move(body.value),
                                query_number(req, "next", 0) != 0),
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

}

}  // namespace tessera::server
