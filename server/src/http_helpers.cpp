#include "http_helpers.h"

#include "connection_guard.h"

namespace tessera::server {

using nlohmann::json;

void send_json(httplib::Response& res, int status, const json& body, bool compact) {
  res.status = status;
  res.set_content((compact ? body.dump() : body.dump(2)) + "\n", "application/json");
}

void send_error(httplib::Response& res, const Status& s) {
  send_json(res, http_status(s.code), json{{"error", s.error}, {"detail", s.detail}});
}

void send(httplib::Response& res, const Status& s, int ok_status) {
  if (!s.ok()) return send_error(res, s);
  send_json(res, ok_status, json{{"ok", true}});
}

bool parse_body(const httplib::Request& req, httplib::Response& res, json& out) {
  if (req.body.empty()) {
    out = json::object();
    return true;
  }
  out = json::parse(req.body, nullptr, false);
  if (out.is_discarded()) {
    send_error(res, make_error(Code::BadRequest, "bad_json", "the request body is not valid JSON"));
    return false;
  }
  return true;
}

bool parse_id(const httplib::Request& req, size_t group, uint64_t& id, httplib::Response& res) {
  try {
    id = std::stoull(req.matches[group].str());
    return true;
  } catch (const std::exception&) {
    send_error(res, make_error(Code::BadRequest, "bad_id", "'" + req.matches[group].str() + "' is not an id"));
    return false;
  }
}

double query_number(const httplib::Request& req, const char* name, double def) {
  if (!req.has_param(name)) return def;
  try {
    return std::stod(req.get_param_value(name));
  } catch (const std::exception&) {
    return def;
  }
}

std::string bundle_of(const httplib::Request& req) {
  if (req.is_multipart_form_data()) return req.has_file("bundle") ? req.get_file_value("bundle").content : "";
  return req.body;
}

std::string peer_of(const httplib::Request& req) { return req.remote_addr + ":" + std::to_string(req.remote_port); }

httplib::Server::Handler Router::watched(httplib::Server::Handler h) const {
  if (!guard_) return h;
  return [guard = guard_, h = std::move(h)](const httplib::Request& req, httplib::Response& res) {
    guard->body_read(peer_of(req));
    h(req, res);
  };
}

httplib::Server::HandlerWithContentReader Router::watched(httplib::Server::HandlerWithContentReader h) const {
  if (!guard_) return h;
  return [guard = guard_, h = std::move(h)](const httplib::Request& req, httplib::Response& res,
                                            const httplib::ContentReader& reader) {
    const std::string peer = peer_of(req);
    const httplib::ContentReader read_then_tell(
        [&](httplib::ContentReceiver receiver) {
          const bool ok = reader(std::move(receiver));
          guard->body_read(peer);
          return ok;
        },
        [&](httplib::MultipartContentHeader header, httplib::ContentReceiver receiver) {
          const bool ok = reader(std::move(header), std::move(receiver));
          guard->body_read(peer);
          return ok;
        });
    h(req, res, read_then_tell);
  };
}

}  // namespace tessera::server
