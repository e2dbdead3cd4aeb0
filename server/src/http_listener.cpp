#include "http_listener.h"

#include "connection_guard.h"
#include "tessera/server/http_api.h"
#include "upload_slots.h"

#include <httplib.h>

#include <sys/socket.h>

#include <chrono>
#include <cstdio>

namespace tessera::server {

namespace {

// The HTTP(S) server with its pool and timeouts; null (with a message) for an unusable certificate.
std::unique_ptr<httplib::Server> make_http_server(const ServerOptions& o, int threads) {
  std::unique_ptr<httplib::Server> http;
  if (!o.tls_cert.empty()) {
    auto ssl = std::make_unique<httplib::SSLServer>(o.tls_cert.c_str(), o.tls_key.c_str());
    if (!ssl->is_valid()) {
      std::fprintf(stderr, "tessera-server: cannot use --tls-cert '%s' with --tls-key '%s' (not PEM, or the key does not match)\n",
                   o.tls_cert.c_str(), o.tls_key.c_str());
      return nullptr;
    }
    http = std::move(ssl);
  } else {
    http = std::make_unique<httplib::Server>();
  }
  http->new_task_queue = [threads] { return new httplib::ThreadPool(size_t(threads)); };
  // A kept-alive idle connection holds an HTTP thread; keep that short so idle clients and
  // workers cannot pin the pool.
  http->set_keep_alive_timeout(2);
  // (A body that stalls is cut off by the connection guard long before this.)
  http->set_read_timeout(60);
  return http;
}

// Binds HOST:PORT (0: any free port); the port bound, or -1.
int bind_http(httplib::Server& http, const std::string& host, int port) {
  // cpp-httplib 0.11 listens with a backlog of 5; a few hundred workers connecting at once would
  // overflow it (dropped handshakes, failed requests). Keep the socket and widen the backlog after
  // bind: listen() on a listening socket only changes its backlog.
  int listen_fd = -1;
  http.set_socket_options([&listen_fd](int fd) {
    httplib::default_socket_options(fd);
    listen_fd = fd;
  });
  const int bound = port == 0 ? http.bind_to_any_port(host) : (http.bind_to_port(host, port) ? port : -1);
  if (bound > 0 && listen_fd >= 0) ::listen(listen_fd, 4096);
  return bound > 0 ? bound : -1;
}

}  // namespace

std::unique_ptr<HttpListener> HttpListener::open(const ServerOptions& o, const std::string& host, int port,
                                                 Coordinator& coordinator, const AuthTokens& tokens,
                                                 ResponseRecorder* recorder, int& exit_code) {
  std::unique_ptr<HttpListener> l(new HttpListener());
  l->uploads_ = std::make_unique<UploadSlots>(SlotLimits{o.max_uploads, o.max_uploads_per_client},
                                              SlotLimits{o.max_result_uploads, o.max_result_uploads_per_host});
  l->threads_ = o.http_threads + l->uploads_->capacity();
  l->http_ = make_http_server(o, l->threads_);
  if (!l->http_) {
    exit_code = 2;
    return nullptr;
  }
  l->port_ = bind_http(*l->http_, host, port);
  if (l->port_ <= 0) {
    std::fprintf(stderr, "tessera-server: cannot listen on %s\n", o.listen.c_str());
    exit_code = 1;
    return nullptr;
  }
  const ConnectionLimits limits{o.header_timeout, o.min_upload_rate, o.upload_grace, !o.tls_cert.empty()};
  l->guard_ = std::make_unique<ConnectionGuard>(l->port_, limits);
  (void)install_routes(*l->http_, coordinator, o.coordinator.max_upload_bytes, tokens,
                       HttpHooks{l->guard_.get(), l->uploads_.get(), recorder});
  return l;
}

HttpListener::~HttpListener() { stop(); }

void HttpListener::start() {
  thread_ = std::thread([this] { http_->listen_after_bind(); });
  // (httplib's stop() does nothing until the server runs: a stop right after start must not hang.)
  for (int i = 0; i < 5000 && !http_->is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void HttpListener::stop() {
  if (http_) http_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace tessera::server
