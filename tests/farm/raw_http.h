// Raw TCP for the attack tests: requests httplib's client would refuse to send (garbage, lying
// lengths, headers trickled byte by byte), with a bound on every wait.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

namespace tessera::test {

class RawConnection {
 public:
  /// To 127.0.0.1:port, from `source` (another loopback address, e.g. "127.0.0.2": another client).
  explicit RawConnection(int port, const char* source = nullptr) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(uint16_t(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    sockaddr_in from{};
    from.sin_family = AF_INET;
    const bool bound = !source || (::inet_pton(AF_INET, source, &from.sin_addr) == 1 &&
                                    ::bind(fd_, reinterpret_cast<sockaddr*>(&from), sizeof from) == 0);
    connected_ = fd_ >= 0 && bound && ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~RawConnection() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool connected() const { return connected_; }
  /// False once the peer has closed (EPIPE/ECONNRESET); never raises SIGPIPE.
  bool send(const std::string& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return false;
      done += size_t(n);
    }
    return true;
  }
  /// True when the server has closed its side (recv returns 0 or an error) within `seconds`.
  /// Anything it sent first is appended to `received`.
  bool closed_within(double seconds, std::string* received = nullptr) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    char buf[4096];
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
      if (left <= 0) return false;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, int(left)) <= 0) continue;
      ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return true;
      if (received) received->append(buf, size_t(n));
    }
  }

 private:
  int fd_;
  bool connected_ = false;
};

/// Sends `request` on a fresh connection and returns everything the server sent before closing
/// it, or within `seconds`.
inline std::string raw_reply(int port, const std::string& request, double seconds = 10) {
  RawConnection c(port);
  if (!c.connected()) return "";
  c.send(request);
  std::string reply;
  c.closed_within(seconds, &reply);
  return reply;
}

/// The HTTP status of a raw reply (0: none, the server just closed).
inline int status_of(const std::string& reply) {
  if (reply.rfind("HTTP/1.", 0) != 0 || reply.size() < 12) return 0;
  return std::atoi(reply.c_str() + 9);
}

/// Sends `request` on a fresh connection and returns the HTTP status of the reply (0: none, the
/// server just closed; -1: no connection), waiting at most `seconds`.
inline int raw_status(int port, const std::string& request, double seconds = 10) {
  RawConnection c(port);
  if (!c.connected()) return -1;
  c.send(request);
  std::string reply;
  c.closed_within(seconds, &reply);
  return status_of(reply);
}

inline std::string raw_request(const std::string& method, const std::string& path, const std::string& token,
                               const std::string& body) {
  std::string r = method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n";
  if (!token.empty()) r += "Authorization: Bearer " + token + "\r\n";
  r += "Content-Type: application/octet-stream\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n";
  return r + body;
}

}  // namespace tessera::test
