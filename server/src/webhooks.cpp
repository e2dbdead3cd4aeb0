#include "webhooks.h"

#include "event_log.h"

#include <httplib.h>

#include <chrono>
#include <utility>

namespace tessera::server {

WebhookSender::WebhookSender() : thread_([this] { loop(); }) {}

WebhookSender::~WebhookSender() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void WebhookSender::send(uint64_t job, std::string url, std::function<std::string()> body) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (queue_.size() >= 10000) {  // a dead endpoint must not grow memory without bound
      ++failed_;
      return;
    }
    queue_.push_back({job, std::move(url), std::move(body), {}});
  }
  cv_.notify_all();
}

uint64_t WebhookSender::delivered() const {
  std::lock_guard<std::mutex> lock(mu_);
  return delivered_;
}

uint64_t WebhookSender::failed() const {
  std::lock_guard<std::mutex> lock(mu_);
  return failed_;
}

bool WebhookSender::post(const Call& call, std::string& error) const {
  // scheme://host[:port]/path: httplib's Client takes the first part, Post the path.
  const size_t scheme_end = call.url.find("://");
  const size_t path_start = call.url.find('/', scheme_end == std::string::npos ? 0 : scheme_end + 3);
  const std::string base = path_start == std::string::npos ? call.url : call.url.substr(0, path_start);
  const std::string path = path_start == std::string::npos ? "/" : call.url.substr(path_start);
  httplib::Client client(base);
  if (!client.is_valid()) {
    error = "not a URL httplib can call";
    return false;
  }
  client.set_connection_timeout(10, 0);
  client.set_read_timeout(10, 0);
  client.set_write_timeout(10, 0);
  auto r = client.Post(path.c_str(), call.body, "application/json");
  if (!r) {
    error = httplib::to_string(r.error());
    return false;
  }
  if (r->status < 200 || r->status >= 300) {
    error = "HTTP " + std::to_string(r->status);
    return false;
  }
  return true;
}

void WebhookSender::loop() {
  std::unique_lock<std::mutex> lock(mu_);
  for (;;) {
    cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, nothing left
    if (stop_) {                 // shutting down: what is queued is dropped, with a trace
      for (const Call& c : queue_)
        log_event(spdlog::level::warn, "webhook.failed", {{"job", c.job}, {"url", c.url}, {"reason", "shutdown"}});
      failed_ += queue_.size();
      queue_.clear();
      return;
    }
    Call call = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    std::string error;
    bool ok = false;
    try {
      call.body = std::exchange(call.make_body, nullptr)();
    } catch (const std::exception& e) {
      error = e.what();
      call.body.clear();
    }
    for (int attempt = 0; attempt < 3 && !ok && !call.body.empty(); ++attempt) {
      if (attempt > 0) {
        std::unique_lock<std::mutex> wait_lock(mu_);
        if (cv_.wait_for(wait_lock, std::chrono::seconds(attempt == 1 ? 1 : 4), [this] { return stop_; })) break;
      }
      ok = post(call, error);
    }
    log_event(ok ? spdlog::level::info : spdlog::level::warn, ok ? "webhook.sent" : "webhook.failed",
              ok ? nlohmann::json{{"job", call.job}, {"url", call.url}}
                 : nlohmann::json{{"job", call.job}, {"url", call.url}, {"reason", error}});
    lock.lock();
    ++(ok ? delivered_ : failed_);
  }
}

}  // namespace tessera::server
