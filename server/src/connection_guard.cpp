#include "connection_guard.h"

#include "event_log.h"
#include "own_sockets.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <dirent.h>
#include <fcntl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <set>

namespace tessera::server {

namespace {

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

}  // namespace

ConnectionGuard::ConnectionGuard(int listen_port, ConnectionLimits limits)
    : listen_port_(listen_port), limits_(limits), thread_([this] { loop(); }) {}

ConnectionGuard::~ConnectionGuard() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void ConnectionGuard::request_started(const std::string& peer) {
  std::lock_guard<std::mutex> lock(mu_);
  Peer& p = peers_[peer];
  p.in_request = true;
  p.since = monotonic_seconds();
}

void ConnectionGuard::body_expected(const std::string& peer, uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mu_);
  Peer& p = peers_[peer];
  p.in_body = bytes > 0;
  p.body_bytes = bytes;
  p.body_seen = false;
  p.last_progress = p.since;
}

void ConnectionGuard::body_read(const std::string& peer) {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = peers_.find(peer);
  if (it != peers_.end()) it->second.in_body = false;
}

std::string ConnectionGuard::body_timeout(const std::string& peer) {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = peers_.find(peer);
  return it == peers_.end() ? std::string() : it->second.timed_out;
}

void ConnectionGuard::close_after_answer(const std::string& peer) {
  std::lock_guard<std::mutex> lock(mu_);
  peers_[peer].close = true;
}

void ConnectionGuard::request_finished(const std::string& peer) {
  bool close = false;
  {
    std::lock_guard<std::mutex> lock(mu_);
    Peer& p = peers_[peer];
    close = p.close;  // (a body cut off was shut down by the scan already)
    p = Peer{};
    p.since = monotonic_seconds();
  }
  // The answer is written (the logger runs after it): httplib's next read on this connection ends
  // at once, and it closes the connection instead of reading the refused body as a request.
  if (close) (void)shut_down_connection(listen_port_, peer, SHUT_RDWR);
}

void ConnectionGuard::loop() {
  std::unique_lock<std::mutex> lock(mu_);
  while (!stop_) {
    cv_.wait_for(lock, std::chrono::milliseconds(200));
    if (stop_) break;
    scan(monotonic_seconds());
  }
}

// Under mu_. True when the body of `p`, on socket `fd`, fell behind and was cut off.
bool ConnectionGuard::check_body(int fd, const std::string& name, Peer& p, double now) {
  uint64_t bytes = 0;
  if (!bytes_received(fd, bytes)) return false;
  if (!p.body_seen) {  // bytes before the first look are not counted: the rate is met a scan later
    p.body_seen = true;
    p.first_bytes = p.last_bytes = bytes;
  } else if (bytes > p.last_bytes) {
    p.last_bytes = bytes;
    p.last_progress = now;
  }
  const double grace = limits_.body_grace, rate = limits_.min_body_rate;
  const double late = now - p.since - grace;  // seconds past the grace
  const double got = double(p.last_bytes - p.first_bytes);
  if (now - p.last_progress > grace) {
    p.timed_out = "the body stopped arriving: no byte for " + number(std::floor((now - p.last_progress) * 10) / 10) +
                  " s; a body may pause at most " + number(grace) + " s (tessera-server --upload-grace)";
  } else if (late > 0 && got < rate * late) {
    p.timed_out = "the body arrived at " + number(std::round(got / (now - p.since))) + " bytes/s; after its first " +
                  number(grace) + " s a body must average " + number(rate) +
                  " bytes/s (tessera-server --min-upload-rate, --upload-grace), so this one of " +
                  std::to_string(p.body_bytes) + " bytes had " +
                  number(std::ceil(grace + double(p.body_bytes) / rate)) + " s";
  } else {
    return false;
  }
  // The 408 is written from here: httplib would not write it itself, since it takes a socket that
  // its client has stopped sending on for gone. Over https the bytes would have to be encrypted
  // by httplib's session, so the connection is only closed. The send never blocks: a client that
  // does not read its answer loses it.
  bodies_cut_off_.fetch_add(1);  // (counted before the client can see its answer)
  if (!limits_.tls) {
    const std::string body = nlohmann::json{{"error", "body_too_slow"}, {"detail", p.timed_out}}.dump(2) + "\n";
    const std::string answer = "HTTP/1.1 408 Request Timeout\r\nContent-Type: application/json\r\nContent-Length: " +
                               std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body;
    (void)::send(fd, answer.data(), answer.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  }
  ::shutdown(fd, SHUT_RDWR);
  p.in_body = false;
  log_event(spdlog::level::warn, "connection.cut_off",
            {{"peer", name}, {"reason", "body_too_slow"}, {"detail", p.timed_out}});
  return true;
}

// Under mu_. A connection whose request headers did not arrive within --header-timeout.
void ConnectionGuard::cut_off_headers(int fd, const std::string& name, Peer& p, double now) {
  cut_off_.fetch_add(1);
  ::shutdown(fd, SHUT_RDWR);
  log_event(spdlog::level::warn, "connection.cut_off", {{"peer", name}, {"header_timeout", limits_.header_timeout}});
  p.since = now + 3600;  // once is enough; httplib closes it now
}

// Under mu_ (the request hooks wait at most one scan of the descriptor table).
void ConnectionGuard::scan(double now) {
  DIR* dir = opendir("/proc/self/fd");
  if (!dir) return;
  std::map<uint64_t, std::string> seen;
  while (dirent* e = readdir(dir)) {
    if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
    const int fd = std::atoi(e->d_name);
    if (fd == dirfd(dir)) continue;
    const uint64_t inode = socket_inode(fd);
    if (inode == 0) continue;
    auto known = sockets_.find(inode);
    std::string peer;
    if (known != sockets_.end()) {
      peer = known->second;
    } else {
      peer = accepted_peer(fd, listen_port_);
      if (peer.empty()) continue;
      Peer& p = peers_[peer];
      if (!p.in_request) p.since = now;  // a new connection: its clock starts now
    }
    seen.emplace(inode, peer);
    Peer& p = peers_[peer];
    const bool body = p.in_body, headers_late = !p.in_request && now - p.since > limits_.header_timeout;
    if (!body && !headers_late) continue;
    // A descriptor of our own, checked to be the socket readlink named: httplib closes `fd` without
    // our lock, and the number may meanwhile belong to another client.
    const int own = fcntl(fd, F_DUPFD_CLOEXEC, 0);
    if (own < 0) continue;
    if (socket_inode(own) == inode) {
      if (body) check_body(own, peer, p, now);
      if (headers_late) cut_off_headers(own, peer, p, now);
    }
    ::close(own);
  }
  closedir(dir);
  // Forget peers whose sockets are gone (a later connection may reuse the port). A request too
  // short to have been seen by a scan is kept a while: its socket may yet show up.
  std::set<std::string> live;
  for (auto& [inode, peer] : seen) live.insert(peer);
  for (auto it = peers_.begin(); it != peers_.end();) {
    const bool stale = !live.count(it->first) && (!it->second.in_request || now - it->second.since > 60);
    it = stale ? peers_.erase(it) : std::next(it);
  }
  sockets_ = std::move(seen);
}

}  // namespace tessera::server
