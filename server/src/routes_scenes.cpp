// Scene bundles (uploaded once, by their SHA-256) and the artifacts jobs render with (a guided
// job's guides), which workers download by hash.
#include "http_helpers.h"

#include <fstream>
#include <memory>
#include <vector>

namespace tessera::server {

namespace {

// The file's bytes as the body, read a chunk at a time as the connection takes them (a bundle may
// be gigabytes). Opened now: retention may remove the file meanwhile, and the open file stays whole.
void send_file(httplib::Response& res, const Result<StoredFile>& file) {
  if (!file.ok()) return send_error(res, file.status);
  auto in = std::make_shared<std::ifstream>(file.value.path, std::ios::binary);
  if (!*in) return send_error(res, make_error(Code::Internal, "internal", "cannot read " + file.value.path));
  res.set_content_provider(size_t(file.value.size), "application/octet-stream",
                           [in](size_t offset, size_t length, httplib::DataSink& sink) {
                             std::vector<char> chunk(std::min(length, size_t(1) << 20));
                             in->seekg(std::streamoff(offset));
                             in->read(chunk.data(), std::streamsize(chunk.size()));
                             return in->gcount() > 0 && sink.write(chunk.data(), size_t(in->gcount()));
                           });
}

}  // namespace

void add_scene_routes(Router& r, Coordinator& c) {
  r.post("/api/v1/scenes", [&c](const httplib::Request& req, httplib::Response& res) {
    std::string bundle = bundle_of(req);
    if (bundle.empty())
      return send_error(res, make_error(Code::BadRequest, "no_bundle", "send the bundle as the body or field 'bundle'"));
    send(res, c.upload_scene(bundle), 201);
  });
  r.get(R"(/api/v1/scenes/([0-9a-f]{64}))", [&c](const httplib::Request& req, httplib::Response& res) {
    send_file(res, c.scene_bundle_file(req.matches[1].str()));
  });
  r.get(R"(/api/v1/guides/([0-9a-f]{64}))", [&c](const httplib::Request& req, httplib::Response& res) {
    send_file(res, c.guide_file(req.matches[1].str()));
  });
}

}  // namespace tessera::server
