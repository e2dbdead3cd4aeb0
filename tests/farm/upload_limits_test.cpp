// Slow and stalled uploads against the coordinator's HTTP listener, in-process with small limits:
// a body that stops or trickles is answered 408 within its limit, a body over its limit is
// refused before it is sent, uploads take slots per client address (workers' results slots of
// their own), and /healthz, leases and heartbeats are answered while every upload slot is taken.
#include "connection_guard.h"
#include "coordinator_fixture.h"
#include "http_listener.h"
#include "raw_http.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace tessera::test {
namespace {

// A request's headers, announcing a body of `length` bytes (none of which is sent here).
std::string headers(const std::string& method, const std::string& path, uint64_t length, const std::string& extra = "") {
  return method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\nContent-Type: application/octet-stream\r\n" +
         "Content-Length: " + std::to_string(length) + "\r\n" + extra + "\r\n";
}

// Nothing answered within `seconds`, and the connection still open: the request is being received.
bool still_receiving(RawConnection& c, double seconds = 0.5) {
  std::string reply;
  return !c.closed_within(seconds, &reply) && reply.empty();
}

// A 4xx from a handler that read the body, not a refusal before it (401, 411, 413, 503).
bool is_handlers_refusal(int status) { return status >= 400 && status < 500 && status != 411 && status != 413; }

class UploadLimits : public ::testing::Test {
 protected:
  void start(server::ServerOptions o) {
    o.listen = "127.0.0.1:0";
    int failure = 0;
    listener_ = server::HttpListener::open(o, "127.0.0.1", 0, coordinator_, {}, nullptr, failure);
    ASSERT_TRUE(listener_) << failure;
    listener_->start();
    port_ = listener_->port();
  }
  std::string worker_path(const std::string& tail) {
    if (worker_ == 0) worker_ = add_worker(coordinator_, "w");
    return "/api/v1/workers/" + std::to_string(worker_) + tail;
  }

  TempDir dir_;
  server::Coordinator coordinator_{options(dir_)};
  std::unique_ptr<server::HttpListener> listener_;
  int port_ = 0;
  uint64_t worker_ = 0;
};

// Bodies that stop after 16 bytes, and one that trickles at a tenth of the minimum rate, are each
// answered 408 naming the limit, within the grace (+ 5 s of slack), not after httplib's 60 s read
// timeout.
TEST_F(UploadLimits, StalledAndTricklingBodiesAreAnswered408WithinTheirLimit) {
  server::ServerOptions o;
  o.upload_grace = 1.5;
  o.min_upload_rate = 2000;
  start(o);
  const double bound = o.upload_grace + 5;
  std::vector<std::string> replies(4);
  std::vector<std::thread> clients;
  const std::vector<std::string> paths = {"/api/v1/scenes", "/api/v1/jobs", worker_path("/heartbeat")};
  for (size_t i = 0; i < paths.size(); ++i)
    clients.emplace_back([&, i] {
      RawConnection c(port_);
      if (c.send(headers("POST", paths[i], i == 2 ? 1000 : 2000000000) + std::string(16, 'x')) &&
          !c.closed_within(bound, &replies[i]))
        replies[i] = "still open after " + std::to_string(bound) + " s";
    });
  clients.emplace_back([&] {  // 50 bytes every 0.25 s: 200 bytes/s
    RawConnection c(port_);
    c.send(headers("POST", "/api/v1/scenes", 1000000));
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(bound);
    while (std::chrono::steady_clock::now() < end)
      if (c.closed_within(0.25, &replies[3]) || !c.send(std::string(50, 'x'))) return;
    replies[3] = "still open after " + std::to_string(bound) + " s";
  });
  for (auto& t : clients) t.join();
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(status_of(replies[i]), 408) << paths[i] << ": " << replies[i];
    EXPECT_NE(replies[i].find("\"body_too_slow\""), std::string::npos) << replies[i];
    EXPECT_NE(replies[i].find("--upload-grace"), std::string::npos) << replies[i];
  }
  EXPECT_EQ(status_of(replies[3]), 408) << replies[3];
  EXPECT_NE(replies[3].find("--min-upload-rate"), std::string::npos) << replies[3];
  EXPECT_EQ(listener_->guard().bodies_cut_off(), 4u);
}

// A Content-Length over its route's limit is answered 413 from the headers alone, and the
// connection closed: the client never has to send the body (nor wait for 100 Continue).
TEST_F(UploadLimits, AnOversizedBodyIsRefused413BeforeItIsSent) {
  server::ServerOptions o;
  o.coordinator.max_upload_bytes = 100000;
  start(o);
  for (const std::string& expect : {std::string(), std::string("Expect: 100-continue\r\n")}) {
    RawConnection c(port_);
    ASSERT_TRUE(c.send(headers("POST", "/api/v1/scenes", 50000000, expect)));
    std::string reply;
    EXPECT_TRUE(c.closed_within(5, &reply)) << "the connection stays open: " << reply;
    EXPECT_EQ(status_of(reply), 413) << reply;
    EXPECT_EQ(reply.find("100 Continue"), std::string::npos) << reply;
    EXPECT_NE(reply.find("the limit is 16877216 bytes (tessera-server --max-upload 100000"), std::string::npos) << reply;
  }
  RawConnection message(port_);
  ASSERT_TRUE(message.send(headers("POST", worker_path("/heartbeat"), 5000000)));
  std::string reply;
  EXPECT_TRUE(message.closed_within(5, &reply)) << reply;
  EXPECT_EQ(status_of(reply), 413) << reply;
  EXPECT_NE(reply.find("a JSON message may have at most 1048576"), std::string::npos) << reply;
}

// Two HTTP threads, and every upload slot held by a stalled body: the threads kept for everything
// else still answer /healthz, /metrics, a lease poll and a heartbeat, and one more upload is
// refused 503 at once.
TEST_F(UploadLimits, HealthLeasesAndHeartbeatsAnswerWhileEveryUploadSlotIsTaken) {
  server::ServerOptions o;
  o.http_threads = 2;
  o.max_uploads = 2;
  o.max_result_uploads = o.max_result_uploads_per_host = 1;
  o.upload_grace = 60;  // (the stalled bodies hold their slots for the whole test)
  start(o);
  const std::string lease = worker_path("/lease?wait=0"), heartbeat = worker_path("/heartbeat");
  std::vector<std::unique_ptr<RawConnection>> stalled;
  for (const std::string& path : std::vector<std::string>{"/api/v1/scenes", "/api/v1/jobs", worker_path("/results?lease=1")}) {
    stalled.push_back(std::make_unique<RawConnection>(port_));
    ASSERT_TRUE(stalled.back()->send(headers("POST", path, 100000) + "x"));
    EXPECT_TRUE(still_receiving(*stalled.back())) << path;
  }
  const std::string busy = raw_reply(port_, headers("POST", "/api/v1/scenes", 100000), 5);
  EXPECT_EQ(status_of(busy), 503) << busy;
  EXPECT_NE(busy.find("--max-uploads 2"), std::string::npos) << busy;

  EXPECT_EQ(raw_status(port_, raw_request("GET", "/healthz", "", ""), 5), 200);
  EXPECT_EQ(raw_status(port_, raw_request("GET", "/metrics", "", ""), 5), 200);
  EXPECT_EQ(raw_status(port_, raw_request("POST", lease, "", ""), 5), 204);
  EXPECT_EQ(raw_status(port_, raw_request("POST", heartbeat, "", "{\"leases\": []}"), 5), 200);
  for (auto& c : stalled) EXPECT_TRUE(still_receiving(*c, 0.1)) << "an upload was given up meanwhile";
}

// One upload at a time per client address: a second one from 127.0.0.2 is refused 503 naming the
// limit, while 127.0.0.1 still uploads. Workers' results have slots of their own: a user's
// upload does not take them, and a worker's result upload does not take the user's.
TEST_F(UploadLimits, UploadSlotsAreBoundedPerClientAddressAndWorkersHaveTheirOwn) {
  server::ServerOptions o;
  o.max_uploads_per_client = 1;
  o.max_result_uploads_per_host = 1;
  o.upload_grace = 30;
  start(o);
  const std::string results = worker_path("/results?lease=1");
  RawConnection user(port_, "127.0.0.2");
  ASSERT_TRUE(user.connected()) << "no 127.0.0.2 on this machine's loopback";
  ASSERT_TRUE(user.send(headers("POST", "/api/v1/scenes", 100000) + "x"));
  ASSERT_TRUE(still_receiving(user));

  RawConnection second(port_, "127.0.0.2");
  ASSERT_TRUE(second.send(headers("POST", "/api/v1/jobs", 2) + "{}"));
  std::string reply;
  EXPECT_TRUE(second.closed_within(5, &reply)) << reply;
  EXPECT_EQ(status_of(reply), 503) << reply;
  EXPECT_NE(reply.find("127.0.0.2 is already sending 1 uploads (scenes, jobs), the most one address may "
                       "(tessera-server --max-uploads-per-client 1)"), std::string::npos) << reply;
  // Another address is not held up (its settings are refused by the handler: no scene).
  EXPECT_TRUE(is_handlers_refusal(raw_status(port_, headers("POST", "/api/v1/jobs", 2) + "{}", 5)));
  // The user's slot is not a worker's: a result from 127.0.0.2 is read (and refused as garbage).
  RawConnection worker_there(port_, "127.0.0.2");
  ASSERT_TRUE(worker_there.send(headers("POST", results, 16) + std::string(16, 'x')));
  reply.clear();
  EXPECT_TRUE(worker_there.closed_within(5, &reply) || !reply.empty());
  EXPECT_TRUE(is_handlers_refusal(status_of(reply))) << reply;

  // A worker's stalled result from 127.0.0.1 holds that host's one result slot: a second result
  // is refused, a user's upload from the same address is not.
  RawConnection local_worker(port_);
  ASSERT_TRUE(local_worker.send(headers("POST", results, 100000) + "x"));
  ASSERT_TRUE(still_receiving(local_worker));
  const std::string refused = raw_reply(port_, headers("POST", results, 16) + std::string(16, 'x'), 5);
  EXPECT_EQ(status_of(refused), 503) << refused;
  EXPECT_NE(refused.find("--max-result-uploads-per-host 1"), std::string::npos) << refused;
  EXPECT_TRUE(is_handlers_refusal(raw_status(port_, headers("POST", "/api/v1/jobs", 2) + "{}", 5)));
}

}  // namespace
}  // namespace tessera::test
