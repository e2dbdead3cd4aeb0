#include "response_recorder.h"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstring>

namespace tessera::server {

std::unique_ptr<ResponseRecorder> ResponseRecorder::open(const std::string& path, std::string& error) {
  std::ofstream out(path, std::ios::app | std::ios::binary);
  if (!out) {
    error = "cannot open '" + path + "' for appending: " + std::strerror(errno);
    return nullptr;
  }
  return std::unique_ptr<ResponseRecorder>(new ResponseRecorder(std::move(out)));
}

void ResponseRecorder::record(const httplib::Request& req, const httplib::Response& res) {
  const std::string content_type = res.get_header_value("Content-Type");
  const bool json_body = content_type.rfind("application/json", 0) == 0;
  nlohmann::json line{{"method", req.method},
                      {"path", req.path},
                      {"status", res.status},
                      {"content_type", content_type},
                      {"body", json_body ? res.body : std::string()}};
  writer_.push([this, text = line.dump()] {
    out_ << text << '\n';
    out_.flush();
  });
}

}  // namespace tessera::server
