// A job's unit render times, as its workers report them, and their running median: the yardstick
// for when an outstanding unit is late enough to deserve a speculative copy. Two heaps keep the
// lower and upper halves, so adding is O(log n) and the median O(1) under the coordinator's lock.
#pragma once

#include <functional>
#include <optional>
#include <queue>
#include <vector>

namespace tessera::server {

class UnitTimes {
 public:
  void add(double seconds) {
    if (!(seconds >= 0)) return;  // (NaN or negative: a worker's clock is not trusted)
    if (lower_.empty() || seconds <= lower_.top()) lower_.push(seconds);
    else upper_.push(seconds);
    if (lower_.size() > upper_.size() + 1) move(lower_, upper_);
    else if (upper_.size() > lower_.size()) move(upper_, lower_);
  }
  size_t count() const { return lower_.size() + upper_.size(); }
  /// The median (the lower one of an even count); none before the first unit.
  std::optional<double> median() const {
    if (lower_.empty()) return std::nullopt;
    return lower_.top();
  }

 private:
  template <class From, class To>
  static void move(From& from, To& to) {
    to.push(from.top());
    from.pop();
  }
  std::priority_queue<double> lower_;                                            // max-heap
  std::priority_queue<double, std::vector<double>, std::greater<double>> upper_;  // min-heap
};

}  // namespace tessera::server
