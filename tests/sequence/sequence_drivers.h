// Driving a pass sequencer in the tests: on this machine (run_locally), and as a coordinator
// would, with units leased in a random order among the ready ones and their results delivered
// late, out of order and twice.
#pragma once

#include "toy_technique.h"

#include "tessera/image/image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace tessera::test {

/// A 37 x 23 window (cropped from 41 x 29) with tiles of `tile_size`.
inline SequenceFrame toy_frame(int tile_size) { return SequenceFrame{TileRect{3, 4, 40, 27}, 41, 29, tile_size, false}; }

/// Every kind of pass (pass_program.h), in two per-iteration films combined by inverse variance:
///   0 Tile    samples 0-1    film 0
///   1 Tile    samples 2-3    film 0  (open with pass 0: a tile's results may arrive out of order)
///   2 Paths   samples 4-7    film 0  uses iteration 0, feeds 1 (4 paths a pixel: sums of several)
///   3 Tile    samples 8-9    film 0  barrier: renders with iteration 1
///   4 Tile    samples 10-12  film 1  iteration 1, starts from its tile's pass-3 state
///   5 Paths   samples 13-16  film 1  iteration 1, feeds 2
///   6 Tile    samples 17-20  film 1  barrier: adaptive, iteration 2
///   7 Tile    samples 21-24  film 1  barrier: adaptive, iteration 2, state from pass 6
/// A pass of `kind` over samples [begin, begin + n) into `film`.
inline PassSpec pass_of_kind(UnitKind kind, uint32_t begin, uint32_t n, int film = 0) {
  PassSpec s;
  s.kind = kind;
  s.sample_begin = begin;
  s.samples = n;
  s.film = film;
  return s;
}

inline PassProgram everything_program() {
  PassProgram p;
  p.spp = 25;
  p.films = 2;
  p.combine = FilmCombine::InverseVariance;
  p.paths_per_unit = 53;
  p.adaptive_settings.min_samples = 2;
  const auto pass = pass_of_kind;
  p.passes = {pass(UnitKind::Tile, 0, 2, 0),  pass(UnitKind::Tile, 2, 2, 0),   pass(UnitKind::Paths, 4, 4, 0),
              pass(UnitKind::Tile, 8, 2, 0),  pass(UnitKind::Tile, 10, 3, 1),  pass(UnitKind::Paths, 13, 4, 1),
              pass(UnitKind::Tile, 17, 4, 1), pass(UnitKind::Tile, 21, 4, 1)};
  p.passes[2].uses = 0, p.passes[2].feeds = 1;
  p.passes[3].barrier = true, p.passes[3].uses = 1;
  p.passes[4].uses = 1, p.passes[4].tile_state = true;
  p.passes[5].uses = 1, p.passes[5].feeds = 2;
  p.passes[6].barrier = p.passes[6].adaptive = true, p.passes[6].uses = 2;
  p.passes[7].barrier = p.passes[7].adaptive = p.passes[7].tile_state = true, p.passes[7].uses = 2;
  return p;
}

inline bool has_artifacts(const PassProgram& p) {
  return std::any_of(p.passes.begin(), p.passes.end(), [](const PassSpec& s) { return s.uses || s.feeds; });
}

inline PassSequencer toy_sequencer(const PassProgram& program, int tile_size) {
  return PassSequencer(program, toy_frame(tile_size), has_artifacts(program) ? std::make_unique<ToyBuilder>() : nullptr);
}

struct Outcome {
  Image image;
  std::string sums;  // every film's pixel sums and splat sums, as bytes: what must match bit for bit
  std::vector<std::string> artifacts;  // each built artifact's bytes
  int builds = 0, duplicates = 0, held_back = 0;
  bool stopped = false;
  uint32_t spp = 0;
};

inline Outcome outcome(const PassSequencer& seq) {
  Outcome out;
  out.image = seq.films().image();
  const FilmAssembler& films = seq.films();
  for (int f = 0; films.allocated() && f < seq.program().films; ++f) {
    const Film& film = films.film(f);
    for (int y = film.window().y0; y < film.window().y1; ++y)
      for (int x = film.window().x0; x < film.window().x1; ++x)
        out.sums.append(reinterpret_cast<const char*>(&film.pixel({x, y})), sizeof(PixelSums));
    out.sums.append(reinterpret_cast<const char*>(films.splats(f).data()), films.splats(f).size() * sizeof(double));
  }
  if (const auto* toy = dynamic_cast<const ToyBuilder*>(seq.builder())) {
    out.artifacts = toy->built;
    out.builds = toy->builds;
  }
  out.stopped = seq.stopped();
  out.spp = seq.spp_complete();
  return out;
}

inline Outcome run_local(const PassProgram& program, int tile_size, int threads, uint32_t seed) {
  PassSequencer seq = toy_sequencer(program, tile_size);
  ToyUnits units(seed);
  run_locally(seq, units, threads);
  return outcome(seq);
}

inline void render_and_add(PassSequencer& seq, ToyUnits& units, size_t unit) {
  UnitResult r;
  units.render(seq, seq.work(unit), r);
  std::string error;
  ASSERT_TRUE(seq.check_records(unit, r.records, error)) << error;
  ASSERT_TRUE(seq.add_result(unit, std::move(r)));
}

/// Stores each new artifact as a coordinator does: through its bytes (decoded back), under a name.
inline void store_artifacts(PassSequencer& seq) {
  while (auto made = seq.take_artifact()) {
    std::string error;
    ASSERT_NE(seq.builder()->decode(made->artifact->encode(), error), nullptr) << error;
    seq.artifact_stored(made->iteration, "toy-" + std::to_string(made->iteration));
  }
}

/// Renders ready units in unit order until `passes` passes are open.
inline void drive_until_open(PassSequencer& seq, ToyUnits& units, size_t passes) {
  for (store_artifacts(seq); seq.open_passes() < passes; store_artifacts(seq)) {
    size_t u = 0;
    while (u < seq.num_units() && !seq.ready(u)) ++u;
    ASSERT_LT(u, seq.num_units()) << "nothing is ready";
    render_and_add(seq, units, u);
  }
}

/// A coordinator's schedule: each round leases half the ready units (random ones), then delivers
/// half of the results in flight in a random order, a fifth of them twice.
inline Outcome run_shuffled(PassSequencer& seq, uint32_t seed, uint32_t order);

/// The same on a new sequencer of `program`.
inline Outcome run_shuffled(const PassProgram& program, int tile_size, uint32_t seed, uint32_t order,
                            PassSequencer* keep = nullptr) {
  if (keep) return run_shuffled(*keep, seed, order);
  PassSequencer seq = toy_sequencer(program, tile_size);
  return run_shuffled(seq, seed, order);
}

inline Outcome run_shuffled(PassSequencer& seq, uint32_t seed, uint32_t order) {
  ToyUnits units(seed);
  std::mt19937 rng(order);
  std::vector<std::pair<size_t, UnitResult>> flight;
  std::set<size_t> leased;
  Outcome out;
  int duplicates = 0, held_back = 0;
  while (!seq.complete()) {
    store_artifacts(seq);
    std::vector<size_t> ready;
    for (size_t u = 0; u < seq.num_units(); ++u)
      if (seq.ready(u) && !leased.count(u)) ready.push_back(u);
    std::shuffle(ready.begin(), ready.end(), rng);
    for (size_t k = 0; k < std::max<size_t>(1, ready.size() / 2) && k < ready.size(); ++k) {
      UnitResult r;
      units.render(seq, seq.work(ready[k]), r);  // (what it renders is decided at its lease)
      flight.emplace_back(ready[k], std::move(r));
      leased.insert(ready[k]);
    }
    if (flight.empty()) {
      ADD_FAILURE() << "nothing ready and nothing in flight before the end";
      break;
    }
    std::shuffle(flight.begin(), flight.end(), rng);
    const size_t n = std::max<size_t>(1, flight.size() / 2);
    for (size_t k = 0; k < n; ++k) {
      auto& [u, r] = flight[k];
      held_back += std::any_of(flight.begin() + ptrdiff_t(k) + 1, flight.end(), [u = u](const auto& f) { return f.first < u; });
      const UnitResult copy = r;
      std::string error;
      EXPECT_TRUE(seq.check_records(u, r.records, error)) << error;
      EXPECT_TRUE(seq.add_result(u, std::move(r)));
      if (rng() % 5 == 0) {
        UnitResult again = copy;
        EXPECT_FALSE(seq.add_result(u, std::move(again))) << "a second result of a unit is a duplicate";
        ++duplicates;
      }
    }
    flight.erase(flight.begin(), flight.begin() + ptrdiff_t(n));
  }
  out = outcome(seq);
  out.duplicates = duplicates;
  out.held_back = held_back;
  return out;
}

inline Image film_image(const PassSequencer& seq, int film) { return seq.films().film_image(film); }

/// Pixels whose channels differ in any bit (sizes must match).
inline int64_t differing_pixels(const Image& a, const Image& b) {
  EXPECT_EQ(a.width(), b.width());
  EXPECT_EQ(a.height(), b.height());
  int64_t n = 0;
  for (int y = 0; y < std::min(a.height(), b.height()); ++y)
    for (int x = 0; x < std::min(a.width(), b.width()); ++x)
      for (int c = 0; c < 3; ++c)
        if (const float u = a.at(x, y, c), v = b.at(x, y, c); std::memcmp(&u, &v, sizeof(float)) != 0) {
          ++n;
          break;
        }
  return n;
}

}  // namespace tessera::test
