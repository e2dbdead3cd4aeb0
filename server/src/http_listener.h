// The coordinator's HTTP(S) listener: cpp-httplib's server bound to --listen with its thread pool,
// timeouts, connection guard (slow headers and bodies), upload slots and routes.
//
// Why the pool has --http-threads + every upload slot threads: httplib gives each connection a
// pool thread for its whole life, and its TaskQueue gets an opaque closure at accept time, so a
// connection cannot be admitted or refused by its peer before a thread reads its headers; nor
// would a peer's address tell a local worker's heartbeat from a user's upload (both 127.0.0.1).
// Uploads are the requests that hold a thread for long (as long as their body takes), so each
// takes a slot once its headers are in (upload_slots.h), and the pool has a thread for every slot
// on top of --http-threads: however many uploads stall, --http-threads threads remain for
// /healthz, /metrics, leases and heartbeats. Headers are bounded by --header-timeout, bodies by
// --min-upload-rate and --upload-grace (connection_guard.h). A second listener for workers would
// have done it too, at the cost of a second address in every worker's configuration.
#pragma once

#include "tessera/server/auth.h"
#include "tessera/server/coordinator.h"
#include "tessera/server/server_app.h"

#include <memory>
#include <string>
#include <thread>

namespace httplib {
class Server;
}

namespace tessera::server {

class ConnectionGuard;
class ResponseRecorder;
class UploadSlots;

class HttpListener {
 public:
  /// Binds HOST:PORT (port 0: any free port) and installs the routes. Null, with a message on
  /// stderr and `exit_code` set (2: an unusable certificate, 1: the address cannot be bound), on failure.
  static std::unique_ptr<HttpListener> open(const ServerOptions& o, const std::string& host, int port,
                                            Coordinator& coordinator, const AuthTokens& tokens,
                                            ResponseRecorder* recorder, int& exit_code);
  ~HttpListener();
  HttpListener(const HttpListener&) = delete;
  HttpListener& operator=(const HttpListener&) = delete;

  int port() const { return port_; }
  /// The HTTP threads: --http-threads plus one for every upload slot.
  int threads() const { return threads_; }
  /// Serves on a thread of its own until stop().
  void start();
  void stop();
  const ConnectionGuard& guard() const { return *guard_; }

 private:
  HttpListener() = default;
  std::unique_ptr<httplib::Server> http_;
  std::unique_ptr<ConnectionGuard> guard_;
  std::unique_ptr<UploadSlots> uploads_;
  std::thread thread_;
  int port_ = 0;
  int threads_ = 0;
};

}  // namespace tessera::server
