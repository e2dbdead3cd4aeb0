#include "reaper.h"

#include <algorithm>

namespace tessera::server {

Reaping decide_reaping(std::span<const ReapWorker> workers, std::span<const ReapLease> leases,
                       std::chrono::steady_clock::time_point now, std::chrono::steady_clock::duration dead_after) {
  Reaping r;
  for (const ReapWorker& w : workers)
    if (w.live && now - w.last_seen > dead_after) r.lost_workers.push_back(w.id);
  std::sort(r.lost_workers.begin(), r.lost_workers.end());
  for (const ReapLease& l : leases) {
    if (std::binary_search(r.lost_workers.begin(), r.lost_workers.end(), l.worker)) ++r.leases_of_lost;
    else if (l.expires < now) r.expired_leases.push_back(l.id);
  }
  return r;
}

}  // namespace tessera::server
