// Webhooks: when a job ends (done, failed or cancelled) and its settings name a `webhook` URL,
// the coordinator POSTs the job's status JSON there. Sent from a thread of its own, never under
// the coordinator's lock; each call is tried 3 times (1 s, 4 s apart) with a 10 s timeout, then
// dropped with a "webhook.failed" log event. Delivery is at most once per ending (a coordinator
// killed before sending does not send after restart).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace tessera::server {

class WebhookSender {
 public:
  WebhookSender();
  ~WebhookSender();  // waits at most ~10 s for calls in flight; queued calls still unsent are dropped
  WebhookSender(const WebhookSender&) = delete;
  WebhookSender& operator=(const WebhookSender&) = delete;

  /// `body` is called on the sender's thread, once, before the first attempt.
  void send(uint64_t job, std::string url, std::function<std::string()> body);

  uint64_t delivered() const;
  uint64_t failed() const;

 private:
  struct Call {
    uint64_t job;
    std::string url;
    std::function<std::string()> make_body;
    std::string body;
  };
  void loop();
  bool post(const Call& call, std::string& error) const;

  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Call> queue_;
  bool stop_ = false;
  uint64_t delivered_ = 0, failed_ = 0;
  std::thread thread_;
};

}  // namespace tessera::server
