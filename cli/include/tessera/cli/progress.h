// Progress on long work: a redrawn bar on a terminal, plain lines (at most every few seconds)
// when output is a pipe or a log file.
#pragma once

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace tessera::cli {

class Progress {
 public:
  Progress(std::string label, bool enabled, std::FILE* out = stderr);
  /// Thread-safe; `done` of `total` work units.
  void update(double done, double total);
  void finish();

 private:
  std::string label_;
  bool enabled_, tty_;
  std::FILE* out_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_;
  int last_percent_ = -1;
};

}  // namespace tessera::cli
