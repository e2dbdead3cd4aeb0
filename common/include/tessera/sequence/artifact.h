// Per-pass artifacts: data made at a barrier from everything before it, which later passes render
// with (a guide's SD-tree now; a photon map next). The program names them by iteration
// (PassSpec::uses, PassSpec::feeds); a technique with artifacts gives the sequencer a builder.
//
// An artifact is immutable once made. On the farm it is encoded, stored under the SHA-256 of its
// bytes before any unit that renders with it is leased, fetched once by each worker that needs it,
// checked against that hash, kept in the worker's cache within its memory budget (memory_bytes),
// and deleted by retention once no job names it (docs/architecture.md, "Pass sequencer").
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace tessera {

class Artifact {
 public:
  virtual ~Artifact() = default;
  /// The bytes stored and handed to workers (the same bits for the same artifact).
  virtual std::string encode() const = 0;
  /// What holding it costs a worker in memory.
  virtual size_t memory_bytes() const = 0;
  /// When the technique stepped aside (the passes that use this artifact render without it, as
  /// do those of every later one), the first artifact it did so at: from there on the films hold
  /// samples of one estimator (FilmAssembler::set_alike_from).
  virtual std::optional<uint32_t> stepped_aside_from() const { return std::nullopt; }
};

/// Makes a technique's artifacts, iteration after iteration. Records are a unit's contribution to
/// the next iteration (a guide's training sums, a photon range's photons): they arrive in any order,
/// with the unit they came from; a builder whose artifact depends on their order orders them by
/// unit. Not thread-safe: the sequencer's caller serialises.
class ArtifactBuilder {
 public:
  virtual ~ArtifactBuilder() = default;
  /// Iteration `iteration`: the first (0) from nothing, each later one from the one before and
  /// the records added for it. Called once per iteration, in order, at a barrier.
  virtual std::shared_ptr<const Artifact> build(uint32_t iteration) = 0;
  /// Whether `records` can go into iteration `iteration` (nothing changes).
  [[nodiscard]] virtual bool check_records(uint32_t iteration, std::string_view records,
                                           std::string& error) const = 0;
  /// Adds a unit's checked records to iteration `iteration`.
  virtual void add_records(uint32_t iteration, uint64_t unit, std::string_view records) = 0;
  /// The artifact from its stored bytes (a restarted coordinator); null with `error` if they do
  /// not decode.
  virtual std::shared_ptr<const Artifact> decode(std::string_view bytes, std::string& error) const = 0;
  /// Rebuilding: iteration `iteration` is `artifact` (the latest stored); records for the next
  /// one follow.
  virtual void restore(uint32_t iteration, std::shared_ptr<const Artifact> artifact) = 0;
  /// Frees what the builder holds once the render has ended.
  virtual void release() = 0;
};

}  // namespace tessera
