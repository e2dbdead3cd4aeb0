#include "tessera/client/farm_client.h"

#include <httplib.h>

#include <fstream>

namespace tessera::client {

using nlohmann::json;

namespace {

// What went wrong with no answer, in words (httplib's names, such as "Connection", say little).
std::string transport_error(httplib::Error e) {
  switch (e) {
    case httplib::Error::Connection: return "connection refused or host unreachable";
    case httplib::Error::ConnectionTimeout: return "connection timed out";
    case httplib::Error::Read: return "the connection broke or timed out before the answer";
    case httplib::Error::Write: return "the connection broke while sending";
    case httplib::Error::SSLConnection: return "TLS handshake failed";
    case httplib::Error::SSLServerVerification: return "its certificate did not verify (--ca-file)";
    case httplib::Error::SSLLoadingCerts: return "cannot load the CA certificates";
    default: return httplib::to_string(e);
  }
}

HttpReply reply_of(const std::string& url, const httplib::Result& r) {
  HttpReply out;
  out.url = url;
  if (!r) {
    out.transport = transport_error(r.error());
    return out;
  }
  out.status = r->status;
  out.body = r->body;
  for (auto& [k, v] : r->headers) out.headers[k] = v;
  return out;
}

struct Endpoint {
  const std::string& host;
  int port;
  bool tls;
  const std::string& token;
  const std::string& ca_file;
};

std::unique_ptr<httplib::Client> make_client(const Endpoint& e, double timeout) {
  const std::string base = (e.tls ? "https://" : "http://") + e.host + ":" + std::to_string(e.port);
  auto c = std::make_unique<httplib::Client>(base);
  if (e.tls) {
    // Never talk TLS to a server we cannot verify: a token sent to an impostor is a token lost.
    c->enable_server_certificate_verification(true);
    if (!e.ca_file.empty()) c->set_ca_cert_path(e.ca_file.c_str());
  }
  if (!e.token.empty()) c->set_bearer_token_auth(e.token);
  const time_t sec = time_t(timeout);
  const time_t usec = time_t((timeout - double(sec)) * 1e6);
  c->set_connection_timeout(5, 0);
  c->set_read_timeout(sec, usec);
  c->set_write_timeout(sec, usec);
  c->set_keep_alive(false);
  return c;
}

}  // namespace

nlohmann::json HttpReply::json() const {
  nlohmann::json j = nlohmann::json::parse(body, nullptr, false);
  return j.is_discarded() ? nlohmann::json() : j;
}

std::string HttpReply::describe() const {
  if (status == 0) return url.empty() ? transport : "no answer from " + url + " (" + transport + ")";
  nlohmann::json j = json();
  std::string s = "HTTP " + std::to_string(status);
  if (j.is_object() && j.contains("error") && j["error"].is_string()) {
    s += ' ';
    s += j["error"].get<std::string>();  // (appends, not "x" + string&&: GCC 12 warns on that falsely)
    if (j.contains("detail") && j["detail"].is_string()) {
      s += ": ";
      s += j["detail"].get<std::string>();
    }
  }
  return s;
}

FarmClient::FarmClient(std::string url, std::string token, std::string ca_file)
    : url_(std::move(url)), token_(std::move(token)), ca_file_(std::move(ca_file)) {
  while (!url_.empty() && url_.back() == '/') url_.pop_back();
  std::string rest;
  if (url_.rfind("http://", 0) == 0) {
    rest = url_.substr(7);
  } else if (url_.rfind("https://", 0) == 0) {
    rest = url_.substr(8);
    tls_ = true;
  } else {
    return;
  }
  size_t colon = rest.rfind(':');
  host_ = colon == std::string::npos ? rest : rest.substr(0, colon);
  try {
    port_ = colon == std::string::npos ? (tls_ ? 443 : 80) : std::stoi(rest.substr(colon + 1));
  } catch (const std::exception&) {
    port_ = 0;
  }
}

bool FarmClient::valid(std::string* why) const {
  if (!host_.empty() && port_ > 0 && port_ < 65536) return true;
  if (why) *why = "server URL '" + url_ + "' is not http://HOST:PORT or https://HOST:PORT";
  return false;
}

HttpReply FarmClient::get(const std::string& path, double timeout) const {
  return reply_of(url_, make_client({host_, port_, tls_, token_, ca_file_}, timeout)->Get(path.c_str()));
}

HttpReply FarmClient::get_to_file(const std::string& path, const std::string& file, double timeout) const {
  std::ofstream out;
  int status = 0;
  std::string error_body;
  auto client = make_client({host_, port_, tls_, token_, ca_file_}, timeout);
  httplib::Result r = client->Get(
      path.c_str(),
      [&](const httplib::Response& response) {
        status = response.status;
        if (status >= 200 && status < 300) out.open(file, std::ios::binary | std::ios::trunc);
        return status < 200 || status >= 300 || bool(out);
      },
      [&](const char* data, size_t n) {
        if (status < 200 || status >= 300) return error_body.append(data, n).size() < (size_t(1) << 20);
        return bool(out.write(data, std::streamsize(n)));
      });
  HttpReply reply = reply_of(url_, r);
  reply.body = std::move(error_body);
  out.close();
  if (r && reply.ok() && !out) {
    reply.status = 0;
    reply.url.clear();  // (the server answered; the failure is here)
    reply.transport = "cannot write " + file;
  }
  return reply;
}

HttpReply FarmClient::del(const std::string& path, const json& body, double timeout) const {
  return reply_of(url_, make_client({host_, port_, tls_, token_, ca_file_}, timeout)->Delete(path.c_str(), body.dump(), "application/json"));
}

HttpReply FarmClient::post_json(const std::string& path, const json& body, double timeout) const {
  return reply_of(url_, make_client({host_, port_, tls_, token_, ca_file_}, timeout)->Post(path.c_str(), body.dump(), "application/json"));
}

HttpReply FarmClient::patch_json(const std::string& path, const json& body, double timeout) const {
  return reply_of(url_, make_client({host_, port_, tls_, token_, ca_file_}, timeout)->Patch(path.c_str(), body.dump(), "application/json"));
}

HttpReply FarmClient::post_bytes(const std::string& path, const std::string& bytes, const std::string& type,
                                 double timeout) const {
  return reply_of(url_, make_client({host_, port_, tls_, token_, ca_file_}, timeout)->Post(path.c_str(), bytes, type.c_str()));
}

HttpReply FarmClient::post_settings_and_bundle(const std::string& path, const json& settings, const std::string& bundle,
                                               double timeout) const {
  httplib::MultipartFormDataItems items = {
      {"settings", settings.dump(), "settings.json", "application/json"},
      {"bundle", bundle, "scene.tar.gz", "application/gzip"},
  };
  return reply_of(url_, make_client({host_, port_, tls_, token_, ca_file_}, timeout)->Post(path.c_str(), items));
}

}  // namespace tessera::client
