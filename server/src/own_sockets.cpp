#include "own_sockets.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <linux/tcp.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace tessera::server {

namespace {

int port_of(const sockaddr_storage& a) {
  if (a.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(a).sin_port);
  if (a.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6&>(a).sin6_port);
  return -1;
}

std::string peer_name(const sockaddr_storage& a, socklen_t len) {
  char host[NI_MAXHOST];
  if (getnameinfo(reinterpret_cast<const sockaddr*>(&a), len, host, sizeof host, nullptr, 0, NI_NUMERICHOST) != 0)
    return "";
  return std::string(host) + ":" + std::to_string(port_of(a));
}

}  // namespace

uint64_t socket_inode(int fd) {
  char link[64];
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  ssize_t n = readlink(path.c_str(), link, sizeof link - 1);
  if (n <= 0) return 0;
  link[n] = '\0';
  if (std::strncmp(link, "socket:[", 8) != 0) return 0;
  return std::strtoull(link + 8, nullptr, 10);
}

std::string accepted_peer(int fd, int listen_port) {
  sockaddr_storage local{}, remote{};
  socklen_t llen = sizeof local, rlen = sizeof remote;
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &llen) != 0 || port_of(local) != listen_port) return "";
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&remote), &rlen) != 0) return "";  // the listener itself
  return peer_name(remote, rlen);
}

bool bytes_received(int fd, uint64_t& bytes) {
  // (linux/tcp.h's tcp_info: glibc's lacks the byte counts, which Linux has had since 4.1.)
  struct tcp_info info {};
  socklen_t len = sizeof info;
  if (getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &len) != 0 ||
      len < offsetof(struct tcp_info, tcpi_bytes_received) + sizeof info.tcpi_bytes_received)
    return false;
  bytes = info.tcpi_bytes_received;
  return true;
}

bool shut_down_connection(int listen_port, const std::string& peer, int how) {
  DIR* dir = opendir("/proc/self/fd");
  if (!dir) return false;
  bool found = false;
  while (dirent* e = readdir(dir)) {
    if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
    const int fd = std::atoi(e->d_name);
    if (fd == dirfd(dir) || socket_inode(fd) == 0) continue;
    // A duplicate stays this socket while it is checked and shut down, even if another thread
    // closes `fd` and the number is reused meanwhile.
    const int mine = dup(fd);
    if (mine < 0) continue;
    found = accepted_peer(mine, listen_port) == peer;
    if (found) ::shutdown(mine, how);
    close(mine);
    if (found) break;
  }
  closedir(dir);
  return found;
}

}  // namespace tessera::server
