// The farm's HTTP API (docs/api.md) as typed calls: what tessera-worker, `tessera submit/jobs/
// cancel` and the benchmarks send. The API's paths are spelt here and in the server's routes only.
// Never throws: a transport failure is status 0 in `http`, a 2xx body that does not decode is an
// `error` (and ok() is false).
#pragma once

#include "tessera/client/farm_client.h"
#include "tessera/farm/protocol.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tessera::client {

/// A reply and, for a 2xx answer, its decoded body.
template <class T>
struct ApiReply {
  HttpReply http;
  T value{};
  std::string error;  // a 2xx whose body did not decode
  bool ok() const { return http.ok() && error.empty(); }
  std::string describe() const { return error.empty() ? http.describe() : error; }
};

using tessera::Registration;  // (farm/protocol.h: the coordinator answers with these)
using tessera::ResultAck;

/// One of the worker's hot requests as plain HTTP pieces, for a caller with a transport of its own
/// (the load benchmark's event loop); FarmApi sends exactly these.
struct RequestSpec {
  std::string method, path, content_type, body;
};
RequestSpec lease_request(uint64_t worker, double wait);
RequestSpec result_request(uint64_t worker, uint64_t lease, std::string tile_result, bool want_next);
/// Their answers, decoded as FarmApi decodes them (a 204 to a lease request: no lease).
ApiReply<std::optional<Lease>> decode_lease_reply(HttpReply http);
ApiReply<ResultAck> decode_result_reply(HttpReply http);

class FarmApi {
 public:
  explicit FarmApi(FarmClient http) : http_(std::move(http)) {}
  const FarmClient& http() const { return http_; }
  const std::string& url() const { return http_.url(); }
  bool valid(std::string* why = nullptr) const { return http_.valid(why); }

  // Scenes and jobs (the client token). Job bodies are the JSON of docs/api.md.
  HttpReply upload_scene(const std::string& bundle, double timeout = 600) const;
  /// The bundle written to `file` as it arrives.
  HttpReply download_scene(const std::string& hash, const std::string& file, double timeout = 600) const;
  /// A guided job's guide (guide_artifact.h bytes).
  HttpReply download_guide(const std::string& hash, double timeout = 600) const;
  /// Settings naming an uploaded bundle, or with the bundle in the same request (non-empty `bundle`).
  HttpReply submit_job(const nlohmann::json& settings, const std::string& bundle = "", double timeout = 600) const;
  HttpReply jobs(double timeout = 30) const;
  HttpReply job(uint64_t id, double timeout = 30) const;
  /// format: exr, png or pfm.
  /// `denoised`: the job's denoised image (a job submitted with denoise).
  HttpReply job_image(uint64_t id, const std::string& format, bool denoised = false, double timeout = 300) const;
  HttpReply cancel_job(uint64_t id, double timeout = 30) const;
  HttpReply set_priority(uint64_t id, int priority, double timeout = 30) const;
  HttpReply retry_job(uint64_t id, double timeout = 30) const;
  HttpReply workers(double timeout = 30) const;
  HttpReply drain_worker(uint64_t worker, double timeout = 30) const;
  HttpReply health(double timeout = 5) const;
  HttpReply metrics(double timeout = 30) const;

  // The worker protocol (the worker token).
  ApiReply<Registration> register_worker(const WorkerHello& hello, double timeout = 30) const;
  /// A long poll of up to `wait` seconds: a lease (200), or none for now (204, value empty).
  ApiReply<std::optional<Lease>> lease(uint64_t worker, double wait, double timeout) const;
  /// The ids among `held` the coordinator no longer wants (cancelled, or delivered by another).
  ApiReply<std::vector<uint64_t>> heartbeat(uint64_t worker, const Heartbeat& heartbeat, double timeout = 10) const;
  /// With `want_next`, the answer also carries the worker's next lease when there is work for it
  /// now (one request and one commit instead of two; no long poll).
  ApiReply<ResultAck> upload_result(uint64_t worker, uint64_t lease, const std::string& tile_result,
                                    double timeout = 60, bool want_next = false) const;
  HttpReply fail_lease(uint64_t worker, uint64_t lease, const std::string& error, double timeout = 10) const;
  HttpReply sign_off(uint64_t worker, double timeout = 10) const;

 private:
  FarmClient http_;
};

}  // namespace tessera::client
