// Bearer tokens: a client token (submit, read, cancel) and a worker token (join, lease, upload,
// download scenes). Which token an endpoint needs is decided here, in one table, so the HTTP layer
// only asks. Comparison is constant-time on SHA-256 digests, so neither the token's bytes nor its
// length leak through timing. With no tokens configured the farm is open (a loopback default).
#pragma once

#include <optional>
#include <string>

namespace tessera::server {

enum class Access { Open, Client, Worker, ClientOrWorker };

/// What `method path` needs.
Access required_access(const std::string& method, const std::string& path);

struct AuthTokens {
  std::string client, worker;  // empty: that role needs no token
  bool enabled() const { return !client.empty() || !worker.empty(); }
};

/// True when `authorization` (the request's Authorization header) carries a token that `access`
/// accepts. A role without a configured token accepts anything.
bool authorized(const AuthTokens& tokens, Access access, const std::string& authorization);

/// The token of an `Authorization: Bearer TOKEN` header (scheme in any case), or "" for any other.
std::string bearer_token(const std::string& authorization);

/// Constant-time equality (on SHA-256 digests of both strings).
bool tokens_equal(const std::string& a, const std::string& b);

}  // namespace tessera::server
