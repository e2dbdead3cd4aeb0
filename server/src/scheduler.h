// Which unit a worker asking for work gets: a pure function of the jobs' and leases' state, so the
// policy is unit-tested apart from locks, HTTP and SQLite.
//
// Fresh work first: the highest-priority job (earliest submitted among equals) that has an unleased
// unit in its open passes the worker may take. When no job of equal or higher priority has one, an
// idle worker gets a speculative copy of the oldest overdue unit of a higher-priority job: the last
// units of a job no longer wait on the slowest (or a silently dead) worker. The first result to
// arrive wins. Bounded by construction: a copy is only of a unit with exactly one lease in flight
// (so at most one extra copy), never of a unit whose result is in or being committed, never of the
// worker's own lease, and only once the lease has run longer than the job's speculation threshold
// (a multiple of its median unit time).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace tessera::server {

/// A queued or running job, in submission order.
struct JobCandidate {
  uint64_t job = 0;
  int priority = 0;
  std::optional<size_t> fresh_unit;  // its first unit neither done nor leased, if any
  bool excluded = false;             // the worker failed this job's work too often
};

/// A lease in flight, in the order leases were issued (oldest first).
struct LeaseCandidate {
  uint64_t job = 0;
  int priority = 0;
  size_t unit = 0;
  uint64_t worker = 0;
  unsigned copies = 0;    // leases of the unit in flight, this one included
  bool excluded = false;  // the asking worker may not take this job's work
  bool finished = false;  // the unit's result is in, or being committed: never leased again
  bool overdue = false;   // the lease has run longer than its job's speculation threshold
};

struct UnitChoice {
  uint64_t job = 0;
  size_t unit = 0;
  bool speculative = false;
};

/// The unit for `worker`, or none. With `speculate` false (speculation off, or a worker that still
/// holds a lease: not idle) only fresh units are handed out.
std::optional<UnitChoice> choose_unit(std::span<const JobCandidate> jobs, std::span<const LeaseCandidate> leases,
                                      uint64_t worker, bool speculate);

/// The priority above which a speculative copy beats the fresh choice (the fresh unit's job's
/// priority; the lowest int when there is none): lets the caller skip listing leases when no job
/// outranks it.
int speculation_floor(std::span<const JobCandidate> jobs);

}  // namespace tessera::server
