// What a coordinator service returns: a value or an error that an HTTP handler maps to a status
// code and a JSON body {"error": ..., "detail": ...}. Services never throw to their callers.
#pragma once

#include <string>
#include <utility>

namespace tessera::server {

enum class Code {
  Ok,
  NotYet,           // 202: not made yet (a denoised image being made); ask again
  BadRequest,       // 400: malformed input
  NotFound,         // 404
  Conflict,         // 409: e.g. a worker whose build differs
  Gone,             // 410: the job of a lease was cancelled or has failed
  PayloadTooLarge,  // 413
  Unprocessable,    // 422: well-formed, but the scene or settings cannot be rendered
  TooManyRequests,  // 429: a limit on outstanding work (queued jobs)
  Unavailable,      // 503: shutting down, or too many waiting requests
  Internal,         // 500
  InsufficientStorage,  // 507: the disk is full
};

struct [[nodiscard]] Status {
  Code code = Code::Ok;
  std::string error;   // short, stable: "bad_request", "scene_load_failed", ...
  std::string detail;  // for people: what is wrong and where
  bool ok() const { return code == Code::Ok; }
  static Status success() { return {}; }
};

inline Status make_error(Code code, std::string error, std::string detail) {
  return Status{code, std::move(error), std::move(detail)};
}

template <class T>
struct [[nodiscard]] Result {
  Status status;
  T value{};
  Result(Status s) : status(std::move(s)) {}  // NOLINT: errors convert implicitly
  Result(T v) : value(std::move(v)) {}        // NOLINT: values too
  bool ok() const { return status.ok(); }
};

int http_status(Code code);

}  // namespace tessera::server
