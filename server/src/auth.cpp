#include "tessera/server/auth.h"

#include "tessera/farm/sha256.h"

#include <openssl/crypto.h>

#include <cctype>


namespace tessera::server {

Access required_access(const std::string& method, const std::string& path) {
  if (path == "/healthz") return Access::Open;
  // The dashboard's static files hold no data: the page asks for the client token itself.
  if ((method == "GET" || method == "HEAD") && (path == "/" || path.rfind("/ui/", 0) == 0)) return Access::Open;
  // Nor does the API description.
  if ((method == "GET" || method == "HEAD") && path == "/api/v1/openapi.json") return Access::Open;
  // Draining a worker is an operator's action.
  const std::string drain = "/drain";
  if (path.rfind("/api/v1/workers/", 0) == 0 && path.size() > drain.size() &&
      path.compare(path.size() - drain.size(), drain.size(), drain) == 0)
    return Access::Client;
  if (path.rfind("/api/v1/workers", 0) == 0) {
    // Listing workers is for people (the dashboard, operators); everything else is the protocol.
    return method == "GET" && path == "/api/v1/workers" ? Access::Client : Access::Worker;
  }
  // Workers download bundles; clients may fetch what they uploaded.
  if (method == "GET" && path.rfind("/api/v1/scenes/", 0) == 0) return Access::ClientOrWorker;
  // Guided jobs' learned guides (guide_artifact.h), for workers and for clients who want to look.
  if (method == "GET" && path.rfind("/api/v1/guides/", 0) == 0) return Access::ClientOrWorker;
  if (path.rfind("/api/", 0) == 0) return Access::Client;
  return Access::Client;  // anything else (unknown paths included) is not for strangers
}

bool tokens_equal(const std::string& a, const std::string& b) {
  const Sha256Digest da = sha256(a), db = sha256(b);
  return CRYPTO_memcmp(da.data(), db.data(), da.size()) == 0;
}

std::string bearer_token(const std::string& authorization) {
  // RFC 7235: the scheme is case-insensitive and followed by one or more spaces.
  const std::string scheme = "bearer";
  if (authorization.size() <= scheme.size() || authorization[scheme.size()] != ' ') return "";
  for (size_t i = 0; i < scheme.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(authorization[i])) != scheme[i]) return "";
  const size_t start = authorization.find_first_not_of(' ', scheme.size());
  return start == std::string::npos ? "" : authorization.substr(start);
}

bool authorized(const AuthTokens& tokens, Access access, const std::string& authorization) {
  if (access == Access::Open) return true;
  const std::string given = bearer_token(authorization);
  auto accepts = [&](const std::string& token) { return token.empty() || (!given.empty() && tokens_equal(given, token)); };
  switch (access) {
    case Access::Client: return accepts(tokens.client);
    case Access::Worker: return accepts(tokens.worker);
    case Access::ClientOrWorker: return accepts(tokens.client) || accepts(tokens.worker);
    case Access::Open: return true;
  }
  return false;
}

}  // namespace tessera::server
