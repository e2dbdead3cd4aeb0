// The coordinator's own workers (--local-workers): started with it, restarted when one exits,
// stopped with it, and never outliving it. Each runs in a process group of its own (a terminal's
// Ctrl-C reaches the coordinator, which stops them in order) and is killed by the kernel when the
// coordinator dies, kill -9 included (PR_SET_PDEATHSIG). A worker still holding a slot's cache
// folder at start-up (left by a coordinator that died before it could stop it) is killed first, so
// a slot's name and cache folder are never run twice.
#pragma once

#include "tessera/server/server_app.h"

#include <sys/types.h>

#include <string>
#include <vector>

namespace tessera::server {

class LocalWorkers {
 public:
  /// Starts `o.local_workers` workers of `url`. Must be called on the thread that lives as long as
  /// the process (the main thread): the death signal follows the thread that forked.
  LocalWorkers(const ServerOptions& o, std::string url, std::string token);
  void restart_exited();
  void signal_stop();
  void wait();
  /// The slot's cache folder (DATA_DIR/local-workers/N).
  std::string cache_dir(int slot) const;

 private:
  pid_t spawn(int slot);
  const ServerOptions& o_;
  const std::string binary_, url_, token_;
  const int threads_;
  std::vector<pid_t> pids_;
};

}  // namespace tessera::server
