#include "tessera/client/farm_api.h"

namespace tessera::client {

using nlohmann::json;

namespace {

const std::string kApi = "/api/v1";

std::string job_path(uint64_t id) { return kApi + "/jobs/" + std::to_string(id); }
std::string worker_path(uint64_t id) { return kApi + "/workers/" + std::to_string(id); }

// The decoded 2xx body, or the reason it is not the object the API promises.
template <class T, class Decode>
ApiReply<T> decode(HttpReply http, Decode&& decode_body) {
  ApiReply<T> out;
  out.http = std::move(http);
  if (!out.http.ok()) return out;
  json body = out.http.json();
  if (!body.is_object()) {
    out.error = "the coordinator's answer is not a JSON object";
    return out;
  }
  try {
    decode_body(body, out);
  } catch (const std::exception& e) {  // (nlohmann's type errors name the field)
    out.error = std::string("the coordinator's answer does not decode: ") + e.what();
  }
  return out;
}

}  // namespace

HttpReply FarmApi::upload_scene(const std::string& bundle, double timeout) const {
  return http_.post_bytes(kApi + "/scenes", bundle, "application/gzip", timeout);
}
HttpReply FarmApi::download_scene(const std::string& hash, const std::string& file, double timeout) const {
  return http_.get_to_file(kApi + "/scenes/" + hash, file, timeout);
}
HttpReply FarmApi::download_guide(const std::string& hash, double timeout) const {
  return http_.get(kApi + "/guides/" + hash, timeout);
}
HttpReply FarmApi::submit_job(const json& settings, const std::string& bundle, double timeout) const {
  if (bundle.empty()) return http_.post_json(kApi + "/jobs", settings, timeout);
  return http_.post_settings_and_bundle(kApi + "/jobs", settings, bundle, timeout);
}
HttpReply FarmApi::jobs(double timeout) const { return http_.get(kApi + "/jobs", timeout); }
HttpReply FarmApi::job(uint64_t id, double timeout) const { return http_.get(job_path(id), timeout); }
HttpReply FarmApi::job_image(uint64_t id, const std::string& format, bool denoised, double timeout) const {
  return http_.get(job_path(id) + "/image?format=" + format + (denoised ? "&denoised=1" : ""), timeout);
}
HttpReply FarmApi::cancel_job(uint64_t id, double timeout) const { return http_.del(job_path(id), json::object(), timeout); }
HttpReply FarmApi::set_priority(uint64_t id, int priority, double timeout) const {
  return http_.patch_json(job_path(id), json{{"priority", priority}}, timeout);
}
HttpReply FarmApi::retry_job(uint64_t id, double timeout) const {
  return http_.post_json(job_path(id) + "/retry", json::object(), timeout);
}
HttpReply FarmApi::workers(double timeout) const { return http_.get(kApi + "/workers", timeout); }
HttpReply FarmApi::drain_worker(uint64_t worker, double timeout) const {
  return http_.post_json(worker_path(worker) + "/drain", json::object(), timeout);
}
HttpReply FarmApi::health(double timeout) const { return http_.get("/healthz", timeout); }
HttpReply FarmApi::metrics(double timeout) const { return http_.get("/metrics", timeout); }

ApiReply<Registration> FarmApi::register_worker(const WorkerHello& hello, double timeout) const {
  return decode<Registration>(http_.post_json(kApi + "/workers", to_json(hello), timeout),
                              [](const json& j, ApiReply<Registration>& out) {
                                out.value.id = j.at("id").get<uint64_t>();
                                out.value.lease_timeout = j.value("lease_timeout", 30.0);
                                out.value.heartbeat_seconds = j.value("heartbeat_seconds", 5.0);
                                out.value.max_poll_wait = j.value("max_poll_wait", 30.0);
                              });
}

RequestSpec lease_request(uint64_t worker, double wait) {
  return {"POST", worker_path(worker) + "/lease?wait=" + std::to_string(wait), "application/json", "{}"};
}

RequestSpec result_request(uint64_t worker, uint64_t lease, std::string tile_result, bool want_next) {
  return {"POST", worker_path(worker) + "/results?lease=" + std::to_string(lease) + (want_next ? "&next=1" : ""),
          "application/x-tessera-tile", std::move(tile_result)};
}

ApiReply<std::optional<Lease>> decode_lease_reply(HttpReply http) {
  if (http.status == 204) return {std::move(http), std::nullopt, ""};
  return decode<std::optional<Lease>>(std::move(http), [](const json& j, ApiReply<std::optional<Lease>>& out) {
    Lease lease;
    if (lease_from_json(j, lease, out.error)) out.value = std::move(lease);
    else out.error = "bad lease from the coordinator: " + out.error;
  });
}

ApiReply<ResultAck> decode_result_reply(HttpReply http) {
  return decode<ResultAck>(std::move(http), [](const json& j, ApiReply<ResultAck>& out) {
    out.value.accepted = j.value("accepted", false);
    out.value.duplicate = j.value("duplicate", false);
    if (!j.contains("lease") || j["lease"].is_null()) return;
    Lease next;
    if (lease_from_json(j["lease"], next, out.error)) out.value.next = std::move(next);
    else out.error = "bad lease from the coordinator: " + out.error;
  });
}

ApiReply<std::optional<Lease>> FarmApi::lease(uint64_t worker, double wait, double timeout) const {
  const RequestSpec r = lease_request(worker, wait);
  return decode_lease_reply(http_.post_bytes(r.path, r.body, r.content_type, timeout));
}

ApiReply<std::vector<uint64_t>> FarmApi::heartbeat(uint64_t worker, const Heartbeat& heartbeat, double timeout) const {
  return decode<std::vector<uint64_t>>(
      http_.post_json(worker_path(worker) + "/heartbeat", heartbeat_to_json(heartbeat), timeout),
      [](const json& j, ApiReply<std::vector<uint64_t>>& out) { out.value = j.at("drop").get<std::vector<uint64_t>>(); });
}

ApiReply<ResultAck> FarmApi::upload_result(uint64_t worker, uint64_t lease, const std::string& tile_result,
                                           double timeout, bool want_next) const {
  const RequestSpec r = result_request(worker, lease, tile_result, want_next);
  return decode_result_reply(http_.post_bytes(r.path, r.body, r.content_type, timeout));
}

HttpReply FarmApi::fail_lease(uint64_t worker, uint64_t lease, const std::string& error, double timeout) const {
  return http_.post_json(worker_path(worker) + "/leases/" + std::to_string(lease) + "/fail", json{{"error", error}},
                         timeout);
}

HttpReply FarmApi::sign_off(uint64_t worker, double timeout) const {
  return http_.del(worker_path(worker), json::object(), timeout);
}

}  // namespace tessera::client
