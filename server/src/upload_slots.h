// How many uploads the coordinator receives at once. A body being received holds an HTTP thread for
// as long as its client takes to send it, so every upload takes a slot before its body is read:
// bundles (POST /api/v1/scenes, /api/v1/jobs) and workers' results each have slots of their own,
// bounded for all clients together and for one client address. Local workers share the
// coordinator's address (127.0.0.1), so a user uploading from that machine must not take the
// workers' slots, nor they the user's. The HTTP pool has a thread for every slot on top of
// --http-threads (http_listener.cpp): uploads, however slow, never take the threads that answer
// /healthz, leases and heartbeats.
#pragma once

#include "tessera/server/status.h"

#include <map>
#include <mutex>
#include <string>

namespace tessera::server {

enum class UploadKind { Bundle, Result };

struct SlotLimits {
  int total = 0;        // all clients together
  int per_address = 0;  // one client address
};

class UploadSlots {
 public:
  UploadSlots(SlotLimits bundles, SlotLimits results);

  /// A slot of `kind` for the request of `peer` ("address:port", one connection) from `address`;
  /// success when the peer holds one already (asked again after `Expect: 100-continue`).
  /// Unavailable (503), naming the limit and its flag, when none is free.
  [[nodiscard]] Status acquire(const std::string& peer, const std::string& address, UploadKind kind);
  /// Frees the peer's slot, if it holds one: its request has been answered.
  void release(const std::string& peer);
  /// Every slot of both kinds: the threads the HTTP pool keeps for uploads.
  int capacity() const;

 private:
  struct Holder {
    UploadKind kind;
    std::string address;
  };
  struct Kind {
    SlotLimits limits;
    int in_use = 0;
    std::map<std::string, int> by_address;
  };
  Kind& of(UploadKind kind) { return kind == UploadKind::Bundle ? bundles_ : results_; }

  mutable std::mutex mu_;
  Kind bundles_, results_;
  std::map<std::string, Holder> holders_;  // by peer
};

}  // namespace tessera::server
