// What operators and monitoring read: /healthz, /metrics, the dashboard and the API description.
#include "dashboard.h"
#include "http_helpers.h"

namespace tessera::server {

void add_operation_routes(Router& r, Coordinator& c) {
  r.get("/healthz", [&c](const httplib::Request&, httplib::Response& res) { send_json(res, 200, to_json(c.health())); });
  r.add(install_dashboard(r.http()));
  r.get("/metrics", [&c](const httplib::Request&, httplib::Response& res) {
    res.set_content(c.metrics(), "text/plain; version=0.0.4");
  });
}

}  // namespace tessera::server
