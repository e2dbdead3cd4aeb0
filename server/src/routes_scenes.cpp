// Scene bundles (uploaded once, by their SHA-256) and the artifacts jobs render with (a guided
// job's guides), which workers download by hash.
#include "http_helpers.h"

namespace tessera::server {

void add_scene_routes(Router& r, Coordinator& c) {
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
}

}  // namespace tessera::server
