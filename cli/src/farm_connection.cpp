#include "farm_connection.h"

#include <cstdlib>
#include <iostream>

namespace tessera::cli {

std::string default_server_url() {
  const char* env = std::getenv("TESSERA_SERVER");
  return env && *env ? env : "http://127.0.0.1:8420";
}

bool connect(const ConnectionOptions& c, const char* who, client::FarmApi& out) {
  try {
    out = client::FarmApi(client::FarmClient(c.server.empty() ? default_server_url() : c.server,
                                             resolve_token("", c.token_file, "TESSERA_CLIENT_TOKEN"), c.ca_file));
  } catch (const std::exception& e) {
    std::cerr << who << ": " << e.what() << "\n";
    return false;
  }
  std::string why;
  if (!out.valid(&why)) {
    std::cerr << who << ": " << why << "\n";
    return false;
  }
  return true;
}

std::string farm_error(const client::HttpReply& reply, const ConnectionOptions& c) {
  std::string out = reply.describe();
  if (reply.status != 401) return out;
  const char* env = std::getenv("TESSERA_CLIENT_TOKEN");
  if (!c.token_file.empty()) out += "; the coordinator refused the client token from --token-file " + c.token_file;
  else if (env && *env) out += "; the coordinator refused the client token in $TESSERA_CLIENT_TOKEN";
  else out += "; the coordinator wants a client token and none was sent";
  return out + " (give its --client-token: set TESSERA_CLIENT_TOKEN=TOKEN or pass --token-file FILE)";
}

}  // namespace tessera::cli
