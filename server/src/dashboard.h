// The coordinator's web dashboard: three static files (server/web/) compiled into the binary by
// server/embed_web.cmake, served at `/` and `/ui/`, and the API description beside them. The page itself talks to /api/v1 with the
// token the user pastes; serving it needs no token (auth.cpp).
#pragma once

#include "tessera/server/http_api.h"

#include <cstddef>
#include <string_view>
#include <vector>

namespace httplib {
class Server;
}

namespace tessera::server {

/// One embedded file, named by its file name in server/web/ ("app.js").
struct WebAsset {
  const char* name;
  const unsigned char* data;
  size_t size;
};

// Defined in the generated web_assets.cpp.
extern const WebAsset kWebAssets[];
extern const size_t kWebAssetCount;

/// The embedded file called `name`, or nullptr.
const WebAsset* find_web_asset(std::string_view name);

/// GET `/` (index.html), `/ui/app.js` and `/ui/style.css`, never cached by the browser (a new
/// server build must not run with yesterday's script), and `/api/v1/openapi.json` (the API
/// description, docs/openapi.json); returns the routes it registered.
std::vector<Route> install_dashboard(httplib::Server& http);

}  // namespace tessera::server
