#include "dashboard.h"

#include <httplib.h>

#include <string>

namespace tessera::server {

namespace {

struct StaticRoute {
  const char* path;  // an httplib route: a regex
  const char* asset;
  const char* content_type;
};

constexpr StaticRoute kRoutes[] = {
    {"/", "index.html", "text/html; charset=utf-8"},
    {R"(/ui/app\.js)", "app.js", "text/javascript; charset=utf-8"},
    {R"(/ui/style\.css)", "style.css", "text/css; charset=utf-8"},
    {R"(/api/v1/openapi\.json)", "openapi.json", "application/json"},
};

}  // namespace

const WebAsset* find_web_asset(std::string_view name) {
  for (size_t i = 0; i < kWebAssetCount; ++i)
    if (name == kWebAssets[i].name) return &kWebAssets[i];
  return nullptr;
}

std::vector<Route> install_dashboard(httplib::Server& http) {
  std::vector<Route> routes;
  for (const StaticRoute& route : kRoutes) {
    const WebAsset* asset = find_web_asset(route.asset);
    if (!asset) continue;  // not embedded (server/CMakeLists.txt lists the files): a 404
    routes.push_back({"GET", route.path});
    const std::string content_type = route.content_type;
    http.Get(route.path, [asset, content_type](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      res.set_header("X-Content-Type-Options", "nosniff");
      res.set_content(reinterpret_cast<const char*>(asset->data), asset->size, content_type);
    });
  }
  return routes;
}

}  // namespace tessera::server
