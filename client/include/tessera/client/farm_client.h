// The transport under FarmApi (farm_api.h): HTTP(S) requests to one coordinator with its bearer
// token. Never throws: transport failures are status 0. Tests of the HTTP surface use it directly.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>

namespace tessera::client {

struct HttpReply {
  int status = 0;          // 0: no answer (connection refused, timeout, ...)
  std::string body;
  std::string transport;   // what went wrong when status == 0
  std::string url;         // the server asked (empty when the failure was local, as a file not written)
  std::map<std::string, std::string> headers;
  bool ok() const { return status >= 200 && status < 300; }
  /// The body as JSON (null if it is not).
  nlohmann::json json() const;
  /// "HTTP 422 scene_load_failed: <detail>", or with no answer "no answer from URL (why)": for
  /// messages.
  std::string describe() const;
};

class FarmClient {
 public:
  /// `url`: http://HOST:PORT or https://HOST:PORT (a trailing slash is fine); `token`: sent as a
  /// bearer token if set. Over https the server's certificate is always verified: against
  /// `ca_file` (PEM) when given, else against the system's trust store.
  explicit FarmClient(std::string url, std::string token = "", std::string ca_file = "");
  const std::string& url() const { return url_; }
  /// False with a message if the URL is not http(s)://HOST[:PORT].
  bool valid(std::string* why = nullptr) const;

  HttpReply get(const std::string& path, double timeout_seconds = 30) const;
  /// GET with a 2xx body written to `file` as it arrives (never held whole: a bundle may be
  /// gigabytes); the reply's body is empty then, an error answer's kept (it is small).
  HttpReply get_to_file(const std::string& path, const std::string& file, double timeout_seconds = 600) const;
  HttpReply del(const std::string& path, const nlohmann::json& body = nlohmann::json::object(),
                double timeout_seconds = 30) const;
  HttpReply post_json(const std::string& path, const nlohmann::json& body, double timeout_seconds = 30) const;
  HttpReply patch_json(const std::string& path, const nlohmann::json& body, double timeout_seconds = 30) const;
  HttpReply post_bytes(const std::string& path, const std::string& bytes, const std::string& content_type,
                       double timeout_seconds = 60) const;
  /// multipart/form-data with a JSON field "settings" and a file field "bundle".
  HttpReply post_settings_and_bundle(const std::string& path, const nlohmann::json& settings,
                                     const std::string& bundle, double timeout_seconds = 600) const;

 private:
  std::string url_, host_, token_, ca_file_;
  int port_ = 0;
  bool tls_ = false;
};

}  // namespace tessera::client
