// `tessera-server --record-responses FILE`: every answer the coordinator sends, one JSON object a
// line: {"method", "path", "status", "content_type", "body"}, with the body's text for JSON answers
// (else ""). It is how the API description (docs/openapi.json) is checked against real traffic
// (tests/docs/openapi_responses_test.py). Lines are written and flushed by a thread of their own,
// so a request never waits on the disk, and a killed server leaves every line it had written.
#pragma once

#include "background_queue.h"

#include <fstream>
#include <memory>
#include <string>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace tessera::server {

class ResponseRecorder {
 public:
  /// Opens FILE for appending; nullptr and `error` when it cannot be.
  static std::unique_ptr<ResponseRecorder> open(const std::string& path, std::string& error);
  void record(const httplib::Request& req, const httplib::Response& res);

 private:
  explicit ResponseRecorder(std::ofstream out) : out_(std::move(out)) {}
  std::ofstream out_;
  BackgroundQueue writer_;  // declared after out_: stops (running what is queued) before out_ closes
};

}  // namespace tessera::server
