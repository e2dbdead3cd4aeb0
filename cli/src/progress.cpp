#include "tessera/cli/progress.h"

#include <unistd.h>

#include <algorithm>

namespace tessera::cli {

Progress::Progress(std::string label, bool enabled, std::FILE* out)
    : label_(std::move(label)), enabled_(enabled), tty_(isatty(fileno(out)) != 0), out_(out) {
  start_ = last_ = std::chrono::steady_clock::now();
}

void Progress::update(double done, double total) {
  if (!enabled_ || total <= 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  double frac = std::clamp(done / total, 0.0, 1.0);
  int percent = int(frac * 100.0);
  auto now = std::chrono::steady_clock::now();
  double elapsed = std::chrono::duration<double>(now - start_).count();
  double since_last = std::chrono::duration<double>(now - last_).count();
  double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
  if (tty_) {
    if (percent == last_percent_ && since_last < 0.25) return;
    const int width = 40;
    int filled = int(frac * width);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(width - filled), '.');
    std::fprintf(out_, "\r%s [%s] %3d%%  %.1fs elapsed, ~%.1fs left ", label_.c_str(), bar.c_str(), percent,
                 elapsed, eta);
    std::fflush(out_);
  } else {
    // Logs get a line per 10% or every 5 s, whichever comes first.
    if (percent / 10 == last_percent_ / 10 && since_last < 5.0) return;
    std::fprintf(out_, "%s: %d%% (%.1fs elapsed, ~%.1fs left)\n", label_.c_str(), percent, elapsed, eta);
  }
  last_percent_ = percent;
  last_ = now;
}

void Progress::finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (tty_) std::fprintf(out_, "\n");
  std::fflush(out_);
}

}  // namespace tessera::cli
