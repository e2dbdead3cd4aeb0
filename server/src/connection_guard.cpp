#include "connection_guard.h"

#include "event_log.h"

#include <spdlog/spdlog.h>

#include <arpa/inet.h>
#include <dirent.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <set>

namespace tessera::server {

namespace {

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int port_of(const sockaddr_storage& a) {
  if (a.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(a).sin_port);
  if (a.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6&>(a).sin6_port);
  return -1;
}

// "address:port" exactly as httplib writes remote_addr (getnameinfo, numeric) and remote_port.
std::string peer_name(const sockaddr_storage& a, socklen_t len) {
  char host[NI_MAXHOST];
  if (getnameinfo(reinterpret_cast<const sockaddr*>(&a), len, host, sizeof host, nullptr, 0, NI_NUMERICHOST) != 0)
    return "";
  return std::string(host) + ":" + std::to_string(port_of(a));
}

// The inode of the socket behind `fd` ("socket:[1234]"), 0 if it is not a socket.
uint64_t socket_inode(int fd) {
  char link[64];
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  ssize_t n = readlink(path.c_str(), link, sizeof link - 1);
  if (n <= 0) return 0;
  link[n] = '\0';
  if (std::strncmp(link, "socket:[", 8) != 0) return 0;
  return std::strtoull(link + 8, nullptr, 10);
}

}  // namespace

ConnectionGuard::ConnectionGuard(int listen_port, double header_timeout)
    : listen_port_(listen_port), header_timeout_(header_timeout), thread_([this] { loop(); }) {}

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

void ConnectionGuard::request_finished(const std::string& peer) {
  std::lock_guard<std::mutex> lock(mu_);
  Peer& p = peers_[peer];
  p.in_request = false;
  p.since = monotonic_seconds();
}

void ConnectionGuard::loop() {
  std::unique_lock<std::mutex> lock(mu_);
  while (!stop_) {
    cv_.wait_for(lock, std::chrono::milliseconds(200));
    if (stop_) break;
    scan(monotonic_seconds());
  }
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
      sockaddr_storage local{}, remote{};
      socklen_t llen = sizeof local, rlen = sizeof remote;
      if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &llen) != 0 || port_of(local) != listen_port_) continue;
      if (getpeername(fd, reinterpret_cast<sockaddr*>(&remote), &rlen) != 0) continue;  // the listener itself
      peer = peer_name(remote, rlen);
      if (peer.empty()) continue;
      Peer& p = peers_[peer];
      if (!p.in_request) p.since = now;  // a new connection: its clock starts now
    }
    seen.emplace(inode, peer);
    Peer& p = peers_[peer];
    if (p.in_request || now - p.since <= header_timeout_) continue;
    // Still the same socket (the descriptor may have been closed and reused since readlink)?
    if (socket_inode(fd) != inode) continue;
    ::shutdown(fd, SHUT_RDWR);
    cut_off_.fetch_add(1);
    log_event(spdlog::level::warn, "connection.cut_off", {{"peer", peer}, {"header_timeout", header_timeout_}});
    p.since = now + 3600;  // once is enough; httplib closes it now
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
