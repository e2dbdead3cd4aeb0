// Prometheus text-format pieces for /metrics: cumulative histograms and label escaping.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace tessera::server {

/// Thread-safe: requests observe it after they have released the coordinator's lock.
class Histogram {
 public:
  explicit Histogram(std::vector<double> upper_bounds);
  void observe(double value);
  /// `# HELP`/`# TYPE` lines and the `_bucket{le=...}`, `_sum`, `_count` series.
  std::string render(const std::string& name, const std::string& help) const;

 private:
  mutable std::mutex mu_;
  std::vector<double> bounds_;
  std::vector<uint64_t> counts_;  // per bucket, not cumulative; one more for +Inf
  double sum_ = 0;
  uint64_t count_ = 0;
};

/// A label value with `\`, `"` and newlines escaped as the text format requires.
std::string escape_label(const std::string& value);

/// "# HELP name help\n# TYPE name type\n".
std::string metric_header(const std::string& name, const std::string& type, const std::string& help);

}  // namespace tessera::server
