// The simulated workers of tessera-farm-load: many workers per thread, each a small state machine
// driven by one epoll loop over non-blocking sockets, so a thousand workers cost the machine what
// their requests cost and not a thread each. Requests are the client library's (RequestSpec), one
// connection each with "Connection: close", as tessera-worker's are.
#include "farm_load.h"
#include "synthetic_results.h"

#include "tessera/client/farm_api.h"
#include "tessera/farm/build_fingerprint.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <map>
#include <thread>

namespace tessera::bench {

using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// "http://127.0.0.1:PORT" (the benchmark's own coordinator) as a socket address.
sockaddr_in loopback_address(const std::string& url) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(std::stoi(url.substr(url.rfind(':') + 1))));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return addr;
}

// The status and body of a complete HTTP/1.1 answer read up to the server's close.
client::HttpReply parse_reply(const std::string& raw) {
  client::HttpReply reply;
  const size_t end = raw.find("\r\n\r\n");
  if (raw.rfind("HTTP/1.", 0) != 0 || end == std::string::npos || raw.size() < 12) {
    reply.transport = raw.empty() ? "connection closed without an answer" : "malformed HTTP answer";
    return reply;
  }
  reply.status = std::atoi(raw.c_str() + 9);
  reply.body = raw.substr(end + 4);
  return reply;
}

struct Sim {
  int index = 0;
  uint64_t id = 0, rng = 0;
  enum class Kind { Lease, Upload } kind = Kind::Lease;
  int fd = -1;
  std::string out, in;
  size_t sent = 0;
  Clock::time_point t0;
  Lease lease;         // the unit being uploaded (Kind::Upload)
  std::string result;  // its encoded result
  int attempt = 0;
  bool finished = false;
};

class Loop {
 public:
  Loop(SimShared& shared, std::vector<SimStats>& stats) : shared_(shared), stats_(stats) {
    addr_ = loopback_address(shared.url);
    ep_ = epoll_create1(EPOLL_CLOEXEC);
  }
  ~Loop() { ::close(ep_); }
  void run(std::vector<Sim>& sims);

 private:
  void send(Sim& s, client::RequestSpec r);
  void on_ready(Sim& s, uint32_t events);
  void complete(Sim& s, client::HttpReply reply);
  void on_lease(Sim& s, client::HttpReply reply);
  void on_upload(Sim& s, client::HttpReply reply);
  void upload(Sim& s, Lease lease);
  void next_step(Sim& s);  // poll for work, or finish when stopping
  void send_result(Sim& s) {
    send(s, client::result_request(s.id, s.lease.id, s.result, !shared_.stop));
  }
  // After a pause: poll again (Kind::Lease) or send the result again (Kind::Upload).
  void later(Sim& s, double seconds) {
    timers_.emplace(Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)), &s);
  }
  void error(Sim& s, const std::string& what) {
    SimStats& st = stats_[size_t(s.index)];
    if (st.errors++ == 0) st.first_error = what;
  }

  SimShared& shared_;
  std::vector<SimStats>& stats_;
  sockaddr_in addr_{};
  int ep_ = -1;
  size_t active_ = 0;
  std::multimap<Clock::time_point, Sim*> timers_;
  SyntheticResults results_;
};

void Loop::send(Sim& s, client::RequestSpec r) {
  s.out = r.method + " " + r.path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\nContent-Type: " +
          r.content_type + "\r\nContent-Length: " + std::to_string(r.body.size()) + "\r\n\r\n";
  s.out.reserve(s.out.size() + r.body.size());
  s.out += r.body;
  s.sent = 0;
  s.in.clear();
  s.t0 = Clock::now();
  s.fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (s.fd < 0 || (::connect(s.fd, reinterpret_cast<sockaddr*>(&addr_), sizeof(addr_)) != 0 && errno != EINPROGRESS)) {
    if (s.fd >= 0) ::close(s.fd);
    s.fd = -1;
    return complete(s, client::HttpReply{0, "", std::string("connect: ") + std::strerror(errno), "", {}});
  }
  epoll_event ev{};
  ev.events = EPOLLOUT;
  ev.data.ptr = &s;
  epoll_ctl(ep_, EPOLL_CTL_ADD, s.fd, &ev);
}

void Loop::on_ready(Sim& s, uint32_t events) {
  if (s.sent < s.out.size()) {  // writing the request
    const ssize_t n = ::send(s.fd, s.out.data() + s.sent, s.out.size() - s.sent, MSG_NOSIGNAL);
    if (n < 0 && errno != EAGAIN) return complete(s, client::HttpReply{0, "", std::strerror(errno), "", {}});
    if (n > 0) s.sent += size_t(n);
    if (s.sent == s.out.size()) {
      epoll_event ev{};
      ev.events = EPOLLIN;
      ev.data.ptr = &s;
      epoll_ctl(ep_, EPOLL_CTL_MOD, s.fd, &ev);
    }
    return;
  }
  char buf[16384];
  for (;;) {  // reading the answer, up to the server's close
    const ssize_t n = ::recv(s.fd, buf, sizeof(buf), 0);
    if (n > 0) {
      s.in.append(buf, size_t(n));
      continue;
    }
    if (n < 0 && errno == EAGAIN && !(events & (EPOLLHUP | EPOLLERR))) return;
    return complete(s, n == 0 ? parse_reply(s.in) : client::HttpReply{0, "", std::strerror(errno), "", {}});
  }
}

void Loop::complete(Sim& s, client::HttpReply reply) {
  if (s.fd >= 0) {
    epoll_ctl(ep_, EPOLL_CTL_DEL, s.fd, nullptr);
    ::close(s.fd);
    s.fd = -1;
  }
  if (s.kind == Sim::Kind::Lease) on_lease(s, std::move(reply));
  else on_upload(s, std::move(reply));
}

void Loop::next_step(Sim& s) {
  if (shared_.stop) {
    s.finished = true;
    --active_;
    return;
  }
  s.kind = Sim::Kind::Lease;
  send(s, client::lease_request(s.id, shared_.poll_wait));
}

void Loop::on_lease(Sim& s, client::HttpReply reply) {
  const double ms = ms_since(s.t0);
  client::ApiReply<std::optional<Lease>> r = client::decode_lease_reply(std::move(reply));
  SimStats& st = stats_[size_t(s.index)];
  if (r.ok() && r.value) {
    st.lease_ms.push_back(ms);
    return upload(s, std::move(*r.value));
  }
  if (r.ok()) {
    ++st.empty_polls;
    // Answered at once: the coordinator's long-poll slots are full; back off as tessera-worker does.
    if (ms < 500) return later(s, 0.25);
    return next_step(s);
  }
  error(s, "lease request: " + r.describe());
  s.kind = Sim::Kind::Lease;
  later(s, 0.1);
}

void Loop::upload(Sim& s, Lease lease) {
  ++stats_[size_t(s.index)].leased;
  // A lease taken is completed even when stopping: every unit leased must end accepted.
  s.kind = Sim::Kind::Upload;
  s.attempt = 0;
  s.result = results_.encode(lease, s.rng);
  s.lease = std::move(lease);
  send_result(s);
}

void Loop::on_upload(Sim& s, client::HttpReply reply) {
  const double ms = ms_since(s.t0);
  client::ApiReply<client::ResultAck> r = client::decode_result_reply(std::move(reply));
  SimStats& st = stats_[size_t(s.index)];
  if (r.ok()) {
    st.upload_ms.push_back(ms);
    if (r.value.duplicate) {
      ++st.duplicates;
    } else if (r.value.accepted) {
      ++st.accepted;
      ++shared_.accepted;
    } else {
      error(s, "upload answered neither accepted nor duplicate: " + r.http.body);
    }
    if (r.value.next) return upload(s, std::move(*r.value.next));
    return next_step(s);
  }
  // Transport failures and 5xx are retried a few times (the real worker retries for minutes; here
  // a lost upload is a finding); anything else is refused for good.
  if ((r.http.status == 0 || r.http.status >= 500) && ++s.attempt < 3) return later(s, 0.1);
  error(s, "upload of job " + std::to_string(s.lease.job_id) + " unit " + std::to_string(s.lease.tile) + "/" +
               std::to_string(s.lease.pass) + ": " + r.describe());
  s.kind = Sim::Kind::Lease;
  next_step(s);
}

void Loop::run(std::vector<Sim>& sims) {
  active_ = sims.size();
  for (Sim& s : sims) next_step(s);
  epoll_event events[256];
  while (active_ > 0) {
    int timeout_ms = 50;
    if (!timers_.empty())
      timeout_ms = std::clamp(int(std::chrono::duration_cast<std::chrono::milliseconds>(timers_.begin()->first - Clock::now()).count()), 0, 50);
    const int n = epoll_wait(ep_, events, 256, timeout_ms);
    for (int i = 0; i < n; ++i) on_ready(*static_cast<Sim*>(events[i].data.ptr), events[i].events);
    while (!timers_.empty() && timers_.begin()->first <= Clock::now()) {
      Sim* s = timers_.begin()->second;
      timers_.erase(timers_.begin());
      if (s->kind == Sim::Kind::Upload) send_result(*s);
      else next_step(*s);
    }
  }
}

}  // namespace

void run_simulated_workers(int first, int count, SimShared& shared, std::vector<SimStats>& stats) {
  std::vector<Sim> sims(static_cast<size_t>(count));
  try {
    client::FarmApi api(client::FarmClient(shared.url));
    const BuildFingerprint& fp = build_fingerprint();  // the check the real worker passes
    for (int k = 0; k < count; ++k) {
      Sim& s = sims[size_t(k)];
      s.index = first + k;
      s.rng = 0x9E3779B97F4A7C15ull * uint64_t(s.index + 1);
      WorkerHello hello{"load-" + std::to_string(s.index), 1, uint64_t(1) << 30, fp.version, fp.isa, fp.probe};
      client::ApiReply<client::Registration> reg = api.register_worker(hello);
      s.id = reg.ok() ? reg.value.id : 0;
      SimStats& st = stats[size_t(s.index)];
      st.registered = s.id != 0;
      ++shared.registered;
      if (!st.registered && st.errors++ == 0) st.first_error = "registration: " + reg.describe();
    }
    std::erase_if(sims, [](const Sim& s) { return s.id == 0; });
    while (!shared.start && !shared.stop) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    Loop(shared, stats).run(sims);
    for (Sim& s : sims) {
      client::HttpReply off = api.sign_off(s.id);
      SimStats& st = stats[size_t(s.index)];
      st.signed_off = off.ok();
      if (!off.ok() && st.errors++ == 0) st.first_error = "sign-off: " + off.describe();
    }
  } catch (const std::exception& e) {
    SimStats& st = stats[size_t(first)];
    if (st.errors++ == 0) st.first_error = std::string("exception: ") + e.what();
  }
}

}  // namespace tessera::bench
