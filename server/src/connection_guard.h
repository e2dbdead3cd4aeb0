// Cuts off connections that do not finish sending a request's headers in time (slow-loris).
//
// cpp-httplib serves each connection on a pool thread and only bounds each read, so a client
// trickling one header byte every few seconds would hold a thread forever, and a few dozen such
// clients would starve everyone. httplib offers no hook at accept time, so the guard watches this
// process's own sockets: every connected socket on the listening port that is not inside a request
// (between the pre-routing handler, which runs once headers are parsed and before any body is read,
// and the logger, which runs after the response) must complete its next request's headers within
// `header_timeout` seconds of being seen or of its previous response, or it is shut down.
// Sockets are known by their inode, so a reused descriptor number is never mistaken for another.
// Bodies are not covered: they are read only after the token check, from authenticated clients.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace tessera::server {

class ConnectionGuard {
 public:
  ConnectionGuard(int listen_port, double header_timeout);
  ~ConnectionGuard();
  ConnectionGuard(const ConnectionGuard&) = delete;
  ConnectionGuard& operator=(const ConnectionGuard&) = delete;

  /// From httplib's pre-routing handler / logger: the peer's request headers are in / its
  /// response is out. Peers are "address:port", as httplib's remote_addr and remote_port.
  void request_started(const std::string& peer);
  void request_finished(const std::string& peer);

  /// Connections cut off so far (for /metrics and the tests).
  uint64_t cut_off() const { return cut_off_.load(); }

 private:
  struct Peer {
    bool in_request = false;
    double since = 0;  // when it was first seen, its request began, or it was last answered
  };
  void loop();
  void scan(double now);

  const int listen_port_;
  const double header_timeout_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::map<std::string, Peer> peers_;           // by "address:port"
  std::map<uint64_t, std::string> sockets_;     // inode -> peer, for the sockets seen last scan
  std::atomic<uint64_t> cut_off_{0};
  std::thread thread_;
};

}  // namespace tessera::server
