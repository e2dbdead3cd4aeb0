// docs/openapi.json against the coordinator itself: every route it registers is described, every
// described operation is a route, each operation's security is what the server requires, and the
// server serves the description it was built with. (Responses against their schemas:
// tests/docs/openapi_responses_test.py.)
#include "coordinator_fixture.h"
#include "tessera/server/auth.h"
#include "tessera/server/http_api.h"

#include <httplib.h>

#include <regex>
#include <thread>

namespace tessera::test {
namespace {

using nlohmann::json;

std::string spec_text() {
  std::ifstream in(std::string(TESSERA_SOURCE_DIR) + "/docs/openapi.json", std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

struct Operation {
  std::string method, path_template, example_path;
  json spec;
};

// A value for a path parameter that its schema's pattern accepts.
std::string example_value(const json& parameter) {
  const std::string pattern = parameter.at("schema").value("pattern", "");
  for (const std::string& candidate : {std::string("7"), std::string(64, 'a')})
    if (pattern.empty() || std::regex_search(candidate, std::regex(pattern))) return candidate;
  ADD_FAILURE() << "no example value for parameter " << parameter.dump();
  return "?";
}

// Every operation of the description, with its path's parameters filled in.
std::vector<Operation> operations(const json& spec) {
  std::vector<Operation> out;
  for (const auto& [path, item] : spec.at("paths").items()) {
    for (const auto& [method, op] : item.items()) {
      if (method == "parameters") continue;
      json parameters = item.value("parameters", json::array());
      for (const json& p : op.value("parameters", json::array())) parameters.push_back(p);
      std::string example = path;
      for (const json& p : parameters) {
        if (p.at("in") != "path") continue;
        const std::string name = "{" + p.at("name").get<std::string>() + "}";
        const size_t at = example.find(name);
        EXPECT_NE(at, std::string::npos) << path << " has no " << name;
        if (at != std::string::npos) example.replace(at, name.size(), example_value(p));
      }
      EXPECT_EQ(example.find('{'), std::string::npos) << path << ": a path parameter is not declared";
      std::string upper = method;
      for (char& ch : upper) ch = char(std::toupper(static_cast<unsigned char>(ch)));
      out.push_back({upper, path, example, op});
    }
  }
  return out;
}

bool route_matches(const server::Route& route, const Operation& op) {
  return route.method == op.method && std::regex_match(op.example_path, std::regex(route.pattern));
}

class OpenApi : public ::testing::Test {
 protected:
  OpenApi() : coordinator_(options(dir_)) { routes_ = server::install_routes(http_, coordinator_, uint64_t(1) << 30); }
  TempDir dir_;
  server::Coordinator coordinator_;
  httplib::Server http_;
  std::vector<server::Route> routes_;
  json spec_ = json::parse(spec_text());
};

TEST_F(OpenApi, EveryRouteIsDescribedOnce) {
  const std::vector<Operation> ops = operations(spec_);
  ASSERT_GT(routes_.size(), 20u);
  for (const server::Route& route : routes_) {
    int described = 0;
    for (const Operation& op : ops) described += route_matches(route, op) ? 1 : 0;
    EXPECT_EQ(described, 1) << route.method << " " << route.pattern << " is described " << described << " times";
  }
}

TEST_F(OpenApi, EveryDescribedOperationIsARoute) {
  for (const Operation& op : operations(spec_)) {
    int routes = 0;
    for (const server::Route& route : routes_) routes += route_matches(route, op) ? 1 : 0;
    EXPECT_EQ(routes, 1) << op.method << " " << op.path_template << " (as " << op.example_path << ") matches " << routes
                         << " routes";
    EXPECT_TRUE(op.spec.contains("operationId") && op.spec.contains("responses")) << op.path_template;
  }
}

// The security requirement of each operation, as the server's required_access names it.
std::string described_access(const json& op) {
  std::vector<std::string> schemes;
  for (const json& requirement : op.at("security"))
    for (const auto& [name, scopes] : requirement.items()) schemes.push_back(name);
  if (schemes.empty()) return "open";
  if (schemes == std::vector<std::string>{"clientToken"}) return "client";
  if (schemes == std::vector<std::string>{"workerToken"}) return "worker";
  if (schemes == std::vector<std::string>{"clientToken", "workerToken"}) return "client or worker";
  return "unknown";
}

std::string access_name(server::Access a) {
  switch (a) {
    case server::Access::Open: return "open";
    case server::Access::Client: return "client";
    case server::Access::Worker: return "worker";
    case server::Access::ClientOrWorker: return "client or worker";
  }
  return "unknown";
}

TEST_F(OpenApi, SecurityIsWhatTheServerRequires) {
  for (const Operation& op : operations(spec_)) {
    ASSERT_TRUE(op.spec.contains("security")) << op.method << " " << op.path_template;
    EXPECT_EQ(described_access(op.spec), access_name(server::required_access(op.method, op.example_path)))
        << op.method << " " << op.path_template;
  }
}

TEST_F(OpenApi, ServerServesTheDescriptionItWasBuiltWith) {
  EXPECT_EQ(spec_.at("openapi"), "3.1.0");
  EXPECT_EQ(spec_.at("info").at("version"), TESSERA_VERSION);
  const int port = http_.bind_to_any_port("127.0.0.1");
  ASSERT_GT(port, 0);
  std::thread listener([this] { http_.listen_after_bind(); });
  httplib::Client client("127.0.0.1", port);
  const auto reply = client.Get("/api/v1/openapi.json");
  http_.stop();
  listener.join();
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->status, 200);
  EXPECT_EQ(reply->get_header_value("Content-Type"), "application/json");
  EXPECT_TRUE(reply->body == spec_text()) << "the served description differs from docs/openapi.json: rebuild";
}

}  // namespace
}  // namespace tessera::test
