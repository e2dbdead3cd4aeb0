// Jobs: submit (settings, and a bundle in the same request or by hash), list, status, image,
// cancel, a new priority, retry.
#include "http_helpers.h"

namespace tessera::server {

using nlohmann::json;

namespace {

// POST /api/v1/jobs: JSON settings, or a multipart form with fields "settings" and "bundle".
void submit(Coordinator& c, const httplib::Request& req, httplib::Response& res) {
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
  bool out_of_range = false;  // (a well-formed value outside its field's range: 422, as the limits)
  if (!job_request_from_json(settings, request, error, /*require_scene=*/bundle.empty(), &out_of_range))
    return send_error(res, make_error(out_of_range ? Code::Unprocessable : Code::BadRequest, "bad_settings", error));
  send(res, c.submit_job(request, bundle), 201);
}

}  // namespace

void add_job_routes(Router& r, Coordinator& c) {
  r.post("/api/v1/jobs", [&c](const httplib::Request& req, httplib::Response& res) { submit(c, req, res); });
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

}

}  // namespace tessera::server
