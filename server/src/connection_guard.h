// Cuts off connections that send their requests too slowly: headers (slow-loris) and bodies.
//
// cpp-httplib serves each connection on a pool thread and only bounds each read, so a client
// trickling one byte every few seconds would hold a thread forever, and a few dozen such clients
// would starve everyone. httplib offers no hook at accept time, so the guard watches this process's
// own sockets every 200 ms:
// - headers: every connected socket on the listening port that is not inside a request (between the
//   pre-routing handler, which runs once headers are parsed and before any body is read, and the
//   logger, which runs after the response) must complete its next request's headers within
//   `header_timeout` seconds of being seen or of its previous response, or it is shut down.
// - bodies: from its headers until its handler runs, a body must keep arriving (the kernel's count
//   of bytes received on the socket, TCP_INFO): no pause longer than `body_grace` seconds, and
//   `min_body_rate` bytes/s on average once the first `body_grace` seconds are over, so a body of
//   N bytes has at most body_grace + N / min_body_rate seconds. A body that falls behind is
//   answered 408 naming the limit (over https the connection is only closed) and its connection
//   shut down: httplib's read ends at once, and its error handler records the same 408
//   (body_timeout()).
// Sockets are known by their inode, so a reused descriptor number is never mistaken for another.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace tessera::server {

struct ConnectionLimits {
  double header_timeout = 10;    // seconds to send a request's headers
  double min_body_rate = 65536;  // bytes/s a body must average once its grace is over
  double body_grace = 10;        // seconds a body may take to start, and its longest pause
  bool tls = false;              // https: a 408 cannot be written beside httplib's TLS session
};

class ConnectionGuard {
 public:
  ConnectionGuard(int listen_port, ConnectionLimits limits);
  ~ConnectionGuard();
  ConnectionGuard(const ConnectionGuard&) = delete;
  ConnectionGuard& operator=(const ConnectionGuard&) = delete;

  /// From httplib's pre-routing handler / logger: the peer's request headers are in / its
  /// response is out. Peers are "address:port", as httplib's remote_addr and remote_port.
  void request_started(const std::string& peer);
  void request_finished(const std::string& peer);
  /// The request was admitted and its body of `bytes` is to be read: the body watch starts.
  void body_expected(const std::string& peer, uint64_t bytes);
  /// Its handler runs: the body is in (or is read by the handler, which says so when done).
  void body_read(const std::string& peer);
  /// The 408's detail when the peer's body was cut off for arriving too slowly, else "".
  std::string body_timeout(const std::string& peer);
  /// The connection is closed once this request is answered: a refusal before its body, whose
  /// unread bytes must not be taken for the next request.
  void close_after_answer(const std::string& peer);

  /// Connections cut off so far: headers too slow, bodies too slow (for the tests).
  uint64_t cut_off() const { return cut_off_.load(); }
  uint64_t bodies_cut_off() const { return bodies_cut_off_.load(); }

 private:
  struct Peer {
    bool in_request = false;
    double since = 0;  // when it was first seen, its request began, or it was last answered
    bool close = false;      // close the connection once answered
    bool in_body = false;    // its body is being received
    uint64_t body_bytes = 0;
    bool body_seen = false;  // a scan has read the socket's byte count since the body began
    uint64_t first_bytes = 0, last_bytes = 0;  // bytes received at the first and last scan
    double last_progress = 0;                  // when the count last grew
    std::string timed_out;                     // the 408's detail, once cut off
  };
  void loop();
  void scan(double now);
  bool check_body(int fd, const std::string& name, Peer& p, double now);
  void cut_off_headers(int fd, const std::string& name, Peer& p, double now);

  const int listen_port_;
  const ConnectionLimits limits_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::map<std::string, Peer> peers_;           // by "address:port"
  std::map<uint64_t, std::string> sockets_;     // inode -> peer, for the sockets seen last scan
  std::atomic<uint64_t> cut_off_{0}, bodies_cut_off_{0};
  std::thread thread_;
};

}  // namespace tessera::server
