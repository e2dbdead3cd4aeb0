// The pass sequencer's contract (sequence/pass_sequencer.h), with the toy technique: Tile and
// Paths units, tile-wide and image-wide results, artifacts made at barriers, per-pixel state from
// a tile's previous pass, adaptive passes and per-iteration films give the same bits for any
// order of results, thread count and tiling; every decision waits where the program says.
#include "sequence_drivers.h"
#include "toy_technique.h"

#include "tessera/sequence/pass_schedule.h"
#include "tessera/sequence/photon_program.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <set>

namespace tessera::test {
namespace {

constexpr uint32_t kSeed = 9;

TEST(PassSequencer, UnitsCoverTheWindowAndEveryPath) {
  PassSequencer seq = toy_sequencer(everything_program(), 7);
  const TileRect w = seq.frame().window;
  for (uint32_t p = 0; p < seq.num_passes(); ++p) {
    const PassSpec& spec = seq.pass(p);
    std::vector<int> covered(size_t(w.area()), 0);
    uint64_t next_path = uint64_t(spec.sample_begin) * uint64_t(w.area());
    for (uint32_t i = 0; i < seq.units_in(p); ++i) {
      const UnitWork work = seq.work(seq.unit(p, i));
      EXPECT_EQ(work.pass, p);
      EXPECT_EQ(work.index, i);
      EXPECT_EQ(seq.pass_of(seq.unit(p, i)), p);
      if (spec.kind == UnitKind::Paths) {
        EXPECT_EQ(work.path_begin, next_path) << "pass " << p << " unit " << i;
        EXPECT_LE(work.path_end - work.path_begin, seq.program().paths_per_unit);
        next_path = work.path_end;
        continue;
      }
      for (int y = work.rect.y0; y < work.rect.y1; ++y)
        for (int x = work.rect.x0; x < work.rect.x1; ++x) ++covered[size_t((y - w.y0) * w.width() + (x - w.x0))];
    }
    if (spec.kind == UnitKind::Paths)
      EXPECT_EQ(next_path, uint64_t(spec.sample_begin + spec.samples) * uint64_t(w.area())) << "pass " << p;
    else
      EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; })) << "pass " << p;
  }
  EXPECT_EQ(seq.units_in(0), 6u * 4u) << "37 x 23 pixels in tiles of 7";
  EXPECT_EQ(seq.units_in(2), 65u) << "4 x 851 paths in ranges of 53, the last one shorter";
}

TEST(PassSequencer, AnyOrderAnyThreadsAnyTilingTheSameBits) {
  const Outcome one = run_local(everything_program(), 7, 1, kSeed);
  ASSERT_EQ(one.builds, 3) << "iterations 0, 1 and 2 were built";
  EXPECT_NE(one.artifacts[1], one.artifacts[0]) << "iteration 1 learned from its records";
  EXPECT_NE(one.artifacts[2], one.artifacts[1]) << "and iteration 2 from its own";
  for (const auto& [tile, threads] : {std::pair{7, 3}, std::pair{16, 2}, std::pair{5, 4}}) {
    const Outcome other = run_local(everything_program(), tile, threads, kSeed);
    EXPECT_EQ(differing_pixels(one.image, other.image), 0) << "tile " << tile << ", " << threads << " threads";
    EXPECT_TRUE(one.sums == other.sums) << "tile " << tile << ", " << threads << " threads";
    EXPECT_EQ(one.artifacts, other.artifacts);
  }
  for (uint32_t order : {1u, 2u, 3u}) {
    const Outcome shuffled = run_shuffled(everything_program(), 9, kSeed, order);
    EXPECT_EQ(differing_pixels(one.image, shuffled.image), 0) << "delivery order " << order;
    EXPECT_TRUE(one.sums == shuffled.sums) << "delivery order " << order;
    EXPECT_EQ(one.artifacts, shuffled.artifacts) << "delivery order " << order;
    EXPECT_GT(shuffled.duplicates, 0) << "some results were delivered twice";
    EXPECT_GT(shuffled.held_back, 0) << "some results were delivered after later ones";
  }
  // (And the seed matters: the comparisons above are not of constant images.)
  EXPECT_GT(differing_pixels(one.image, run_local(everything_program(), 7, 1, kSeed + 1).image), 0);
}

TEST(PassSequencer, ATilesResultsEnterInPassOrder) {
  // Four passes open at once: a tile's results often arrive out of order (and a sum of three or
  // more of the toy's values depends on their order).
  PassProgram program;
  program.spp = 10;
  for (uint32_t p = 0; p < 4; ++p) program.passes.push_back(PassSpec{UnitKind::Tile, p * (p + 1) / 2, p + 1});
  const Outcome local = run_local(program, 6, 1, kSeed);
  for (uint32_t order : {1u, 2u}) {
    const Outcome shuffled = run_shuffled(program, 6, kSeed, order);
    EXPECT_GT(shuffled.held_back, 0);
    EXPECT_TRUE(local.sums == shuffled.sums) << "delivery order " << order;
  }
}

TEST(PassSequencer, ImageWideResultsAreSummedInUnitOrder) {
  PassProgram program;
  program.spp = 3;
  program.paths_per_unit = 29;
  program.passes = {PassSpec{UnitKind::Paths, 0, 2}, PassSpec{UnitKind::Paths, 2, 1}};
  PassSequencer delivered = toy_sequencer(program, 8);
  const Outcome shuffled = run_shuffled(program, 8, kSeed, 5, &delivered);
  // The same sums made by hand: every unit's splats, units in order, then over the paths per pixel.
  PassSequencer seq = toy_sequencer(program, 8);
  ToyUnits units(kSeed);
  const TileRect w = seq.frame().window;
  std::vector<double> sum(size_t(w.area()) * 3, 0.0);
  for (size_t u = 0; u < seq.num_units(); ++u) {
    UnitResult r;
    units.render(seq, seq.work(u), r);
    for (size_t k = 0; k < r.splats.size(); ++k)
      for (int c = 0; c < 3; ++c) sum[size_t(r.splats.pixel[k]) * 3 + size_t(c)] += r.splats.value[k][size_t(c)];
  }
  EXPECT_TRUE(delivered.films().splats(0) == sum) << "the splat sums, bit for bit";
  int64_t differing = 0;
  for (int y = 0; y < w.height(); ++y)
    for (int x = 0; x < w.width(); ++x)
      for (int c = 0; c < 3; ++c)
        differing += shuffled.image.at(x, y, c) != float(sum[size_t(y * w.width() + x) * 3 + size_t(c)] / 3.0);
  EXPECT_EQ(differing, 0) << "pixel = splat sum / light paths per pixel (3)";
}

TEST(PassSequencer, SplatsFoldedAChunkAtATimeSumToTheSameBits) {
  // A coordinator folds a unit's splats a few thousand at a time, taking its lock for each chunk:
  // the sums are those of folding each unit at once, whatever the chunk size.
  PassProgram program;
  program.spp = 3;
  program.paths_per_unit = 29;
  program.passes = {PassSpec{UnitKind::Paths, 0, 2}, PassSpec{UnitKind::Paths, 2, 1}};
  const Outcome whole = run_shuffled(program, 8, kSeed, 3);
  for (size_t chunk : {size_t(1), size_t(7), size_t(100)}) {
    PassSequencer seq = toy_sequencer(program, 8);
    seq.films().fold_later();
    ToyUnits units(kSeed);
    std::vector<size_t> order(seq.num_units());
    std::iota(order.begin(), order.end(), size_t(0));
    std::shuffle(order.begin(), order.end(), std::mt19937(uint32_t(chunk)));
    for (size_t u : order) {
      render_and_add(seq, units, u);
      if (seq.films().splats_ready()) (void)seq.films().fold_splats(chunk);  // (one chunk per result)
    }
    EXPECT_TRUE(seq.films().splats_held()) << "chunk " << chunk << ": some are left to fold";
    while (seq.films().splats_ready()) (void)seq.films().fold_splats(chunk);
    EXPECT_FALSE(seq.films().splats_held());
    EXPECT_TRUE(outcome(seq).sums == whole.sums) << "chunk " << chunk;
  }
}

TEST(PassSequencer, AnArtifactWaitsForItsBarrierAndItsStore) {
  auto builder = std::make_unique<ToyBuilder>();
  ToyBuilder* toy = builder.get();
  PassSequencer seq(everything_program(), toy_frame(8), std::move(builder));
  ToyUnits units(kSeed);
  auto made = seq.take_artifact();
  ASSERT_TRUE(made);
  EXPECT_EQ(made->iteration, 0u);
  EXPECT_FALSE(seq.take_artifact()) << "handed out once";
  EXPECT_EQ(seq.open_passes(), 2u) << "passes 0 and 1 render with nothing; pass 2 waits for iteration 0's store";
  seq.artifact_stored(0, "h0");
  EXPECT_EQ(seq.open_passes(), 3u) << "pass 2 is open; pass 3 waits at its barrier";
  std::string error;
  EXPECT_FALSE(seq.check_records(seq.unit(0, 0), "x", error)) << "pass 0 feeds nothing";
  EXPECT_FALSE(seq.check_records(seq.unit(2, 0), "short", error)) << error;
  // Everything of passes 0, 1 and 2 but one unit: no barrier yet.
  const size_t last = seq.unit(1, seq.units_in(1) - 1);
  for (size_t u = 0; u < seq.first_unit(3); ++u)
    if (u != last) render_and_add(seq, units, u);
  EXPECT_EQ(toy->builds, 1);
  EXPECT_EQ(seq.open_passes(), 3u);
  render_and_add(seq, units, last);
  EXPECT_EQ(toy->builds, 2) << "the barrier of pass 3 built iteration 1 once passes 0-2 were complete";
  EXPECT_EQ(seq.open_passes(), 3u) << "pass 3 waits for iteration 1 to be stored";
  EXPECT_FALSE(seq.ready(seq.unit(3, 0)));
  made = seq.take_artifact();
  ASSERT_TRUE(made);
  EXPECT_EQ(made->iteration, 1u);
  seq.artifact_stored(1, "h1");
  EXPECT_EQ(seq.open_passes(), 6u) << "passes 3, 4 and 5 render with iteration 1; pass 6 waits at its barrier";
  EXPECT_TRUE(seq.ready(seq.unit(3, 0)));
  EXPECT_EQ(seq.artifact_hash(1), "h1");
  EXPECT_EQ(seq.artifact(0), nullptr) << "only the latest artifact is kept";
}

TEST(PassSequencer, AUnitStartsFromTheStateItsTilesPreviousPassLeft) {
  PassSequencer seq = toy_sequencer(everything_program(), 8);
  ToyUnits units(kSeed);
  drive_until_open(seq, units, 5);  // passes 0..4 open: 4 takes its state from 3
  const size_t a = seq.unit(4, 1), before = seq.unit(3, 1);
  EXPECT_FALSE(seq.ready(a)) << "its tile's pass 3 is not done";
  EXPECT_TRUE(seq.ready(before));
  render_and_add(seq, units, before);
  ASSERT_TRUE(seq.ready(a));
  const UnitWork work = seq.work(a);
  ASSERT_NE(work.tile_state, nullptr);
  // The toy's state counts a pixel's samples along its chain of passes, which starts at pass 3.
  std::vector<uint32_t> state(size_t(work.rect.area()));
  ASSERT_EQ(work.tile_state->size(), state.size() * 4);
  std::memcpy(state.data(), work.tile_state->data(), work.tile_state->size());
  EXPECT_TRUE(std::all_of(state.begin(), state.end(), [](uint32_t s) { return s == 2; }));
}

TEST(PassSequencer, PerIterationFilmsAreCombinedByInverseVariance) {
  PassSequencer seq = toy_sequencer(everything_program(), 8);
  ToyUnits units(kSeed);
  run_locally(seq, units, 2);
  const FilmAssembler& films = seq.films();
  const Image combined = films.image();
  // Each film's own image, by hand: its mean plus its splats over its light paths per pixel,
  // weighted by the inverse of its noise estimate with each pixel's term clamped at 1.
  const double e0 = estimate_noise(films.film(0), 1.0).rel_mse, e1 = estimate_noise(films.film(1), 1.0).rel_mse;
  ASSERT_TRUE(std::isfinite(e0) && std::isfinite(e1));
  const double w0 = 1.0 / (e0 + 1e-12), w1 = 1.0 / (e1 + 1e-12);
  const Image i0 = film_image(seq, 0), i1 = film_image(seq, 1);
  int64_t differing = 0;
  for (int y = 0; y < combined.height(); ++y)
    for (int x = 0; x < combined.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const float expect = float(0.0 + w0 / (w0 + w1) * double(i0.at(x, y, c)) + w1 / (w0 + w1) * double(i1.at(x, y, c)));
        differing += combined.at(x, y, c) != expect;
      }
  EXPECT_EQ(differing, 0);
  EXPECT_NE(e0, e1) << "the films weigh differently";
}

// Films whose passes render as one estimator (a technique that stepped aside) weigh as one film,
// in proportion to their samples: here both films (film 0's last pass uses artifact 1), of 2 + 2 +
// 2 and 3 + 4 + 4 samples per pixel.
TEST(PassSequencer, FilmsOfOneEstimatorWeighByTheirSamples) {
  PassSequencer seq = toy_sequencer(everything_program(), 8);
  ToyUnits units(kSeed);
  run_locally(seq, units, 2);
  seq.films().set_alike_from(1);
  const Image combined = seq.films().image();
  const Image i0 = film_image(seq, 0), i1 = film_image(seq, 1);
  for (int y = 0; y < combined.height(); ++y)
    for (int x = 0; x < combined.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double expect = 6.0 / 17.0 * double(i0.at(x, y, c)) + 11.0 / 17.0 * double(i1.at(x, y, c));
        ASSERT_NEAR(combined.at(x, y, c), expect, 1e-5 * std::abs(expect) + 1e-7) << x << "," << y;
      }
}

TEST(PassSequencer, StopsAtTheTargetErrorAsARenderOfTheSamplesReached) {
  PassProgram program;
  program.spp = 24;
  program.target_error = 0.05;
  uint32_t begin = 0;
  for (uint32_t n : pass_schedule(24)) {
    program.passes.push_back(PassSpec{UnitKind::Tile, begin, n, begin > 0, false, begin > 0});
    begin += n;
  }
  const Outcome stopped = run_shuffled(program, 8, kSeed, 4);
  ASSERT_TRUE(stopped.stopped);
  ASSERT_LT(stopped.spp, 24u);
  PassProgram reached;
  reached.spp = stopped.spp;
  for (const PassSpec& p : program.passes)
    if (p.sample_begin < stopped.spp) reached.passes.push_back(PassSpec{UnitKind::Tile, p.sample_begin, p.samples});
  EXPECT_EQ(differing_pixels(stopped.image, run_local(reached, 5, 2, kSeed).image), 0);
}

TEST(PassProgram, FlawsAreNamed) {
  PassProgram p = everything_program();
  EXPECT_EQ(program_error(p), "");
  auto flaw = [&](auto change) {
    PassProgram q = everything_program();
    change(q);
    return program_error(q);
  };
  EXPECT_NE(flaw([](PassProgram& q) { q.passes[3].barrier = false; }).find("without waiting"), std::string::npos);
  EXPECT_NE(flaw([](PassProgram& q) { q.passes[6].barrier = false; }).find("no barrier"), std::string::npos);
  EXPECT_NE(flaw([](PassProgram& q) { q.passes[4].film = 2; }).find("no such film"), std::string::npos);
  EXPECT_NE(flaw([](PassProgram& q) { q.passes[2].adaptive = true, q.passes[2].barrier = true; }).find("Paths"),
            std::string::npos);
  EXPECT_NE(flaw([](PassProgram& q) { q.passes[0].tile_state = true; }).find("state"), std::string::npos);
  EXPECT_NE(flaw([](PassProgram& q) { q.passes[7].adaptive = false; }).find("adaptive"), std::string::npos);
  EXPECT_NE(flaw([](PassProgram& q) { q.combine = FilmCombine::Sum; }).find("Sum"), std::string::npos);
  EXPECT_THROW(PassSequencer(everything_program(), toy_frame(8)), std::invalid_argument) << "artifacts need a builder";
}

// A light tracer's pass of the same samples as the Tile pass before it: its paths are those
// samples' (path k: sample k / window pixels), and it takes no samples of its own.
TEST(PassProgram, APassOfTheSameSamplesFollowsItsTilePass) {
  PassProgram p;
  p.spp = 5;
  p.paths_per_unit = 50;
  p.passes = {pass_of_kind(UnitKind::Tile, 0, 2), pass_of_kind(UnitKind::Paths, 0, 2), pass_of_kind(UnitKind::Tile, 2, 3),
              pass_of_kind(UnitKind::Paths, 2, 3)};
  p.passes[1].same_samples = p.passes[3].same_samples = true;
  ASSERT_EQ(program_error(p), "");
  const PassSequencer seq(p, toy_frame(8));
  const uint64_t pixels = uint64_t(seq.frame().window.area());
  const UnitWork w = seq.work(seq.unit(3, 0));
  EXPECT_EQ(w.path_begin, 2 * pixels) << "the paths of samples 2, 3 and 4";
  EXPECT_EQ(seq.units_in(3), uint32_t((3 * pixels + 49) / 50));
  auto flawed = [&](auto change) {
    PassProgram q = p;
    change(q);
    return program_error(q);
  };
  EXPECT_NE(flawed([](PassProgram& q) { q.passes[1].sample_begin = 1; }).find("does not follow"), std::string::npos);
  EXPECT_NE(flawed([](PassProgram& q) { q.passes[3].samples = 2; }).find("does not follow"), std::string::npos);
  EXPECT_NE(flawed([](PassProgram& q) { q.passes[2].same_samples = true; }).find("does not follow"), std::string::npos);
  EXPECT_NE(flawed([](PassProgram& q) { q.passes[1].same_samples = false; }).find("do not follow"), std::string::npos);
}

}  // namespace
}  // namespace tessera::test

namespace tessera {
namespace {

// A photon mapper's program (photon_program.h): a photon pass feeds the iteration its gather
// renders with, so iteration 0 is made at the gather's barrier, not at the start; photon units
// are ranges of the pass's own photons; a gather starts from its tile's previous gather, across
// the photon pass between them; only the gathers' samples are the render's.
TEST(PassSequencer, APhotonPassFeedsTheGatherAfterIt) {
  PassProgram p = photon_program(2, 120);
  p.paths_per_unit = 50;
  ASSERT_EQ(program_error(p), "");
  PassSequencer seq(p, test::toy_frame(8), std::make_unique<GridBuilder<Photon>>([](uint32_t) { return 0.5f; }));
  const uint64_t pixels = uint64_t(seq.frame().window.area());
  EXPECT_EQ(seq.planned_samples(), 2 * pixels);
  ASSERT_EQ(seq.units_in(0), 3u);
  EXPECT_FALSE(seq.take_artifact()) << "iteration 0 waits for its photons";
  EXPECT_EQ(seq.open_passes(), 1u);
  const UnitWork last = seq.work(seq.unit(2, 2));
  EXPECT_EQ(std::pair(last.path_begin, last.path_end), std::pair(uint64_t(100), uint64_t(120)));
  EXPECT_EQ(last.sample_begin, 1u) << "the photons of pass 1";
  for (uint32_t i = 0; i < 3; ++i) {
    Photon ph{{float(i), 0.f, 0.f}, {1.f, 1.f, 1.f}, 0, {0, 0}, 2};
    UnitResult r;
    r.splats.reset(seq.frame().window);
    r.records = grid_records(std::vector<Photon>{ph, ph});
    ASSERT_TRUE(seq.add_result(seq.unit(0, i), std::move(r)));
  }
  auto made = seq.take_artifact();
  ASSERT_TRUE(made);
  EXPECT_EQ(made->iteration, 0u);
  EXPECT_EQ(static_cast<const PhotonMapArtifact*>(made->artifact.get())->grid().size(), 6u);
  seq.artifact_stored(0, "h0");
  EXPECT_EQ(seq.open_passes(), 3u) << "the gather, and the next photon pass beside it";
  UnitResult gathered;
  gathered.tile.reset(seq.tiles()[1]);
  gathered.tile_state = "state of tile 1";
  ASSERT_TRUE(seq.add_result(seq.unit(1, 1), std::move(gathered)));
  const UnitWork next = seq.work(seq.unit(3, 1));
  ASSERT_NE(next.tile_state, nullptr);
  EXPECT_EQ(*next.tile_state, "state of tile 1") << "across the photon pass between the gathers";
}

// A coordinator keeps a pass's records, never their grid (PointMapUse::Store), whatever order its
// units arrive in; the bytes it stores decode to the grid a local render builds from them.
TEST(PassSequencer, AStoredPhotonMapIsTheGridARenderBuilds) {
  PassProgram p = photon_program(1, 120);
  p.paths_per_unit = 50;
  auto radius = [](uint32_t) { return 0.25f; };
  PassSequencer local(p, test::toy_frame(8), std::make_unique<GridBuilder<Photon>>(radius));
  PassSequencer farm(p, test::toy_frame(8), std::make_unique<GridBuilder<Photon>>(radius, PointMapUse::Store));
  auto photons_of = [](uint32_t unit) {
    std::vector<Photon> out;
    for (uint32_t k = 0; k < 3 + unit; ++k)
      out.push_back(Photon{{float(unit) * 0.3f, float(k) * 0.2f, 0.f}, {1.f, float(k), 0.5f}, k, {0, 0}, 2});
    return out;
  };
  for (uint32_t i : {0u, 1u, 2u}) {
    UnitResult r;
    r.splats.reset(local.frame().window);
    r.records = grid_records(photons_of(i));
    ASSERT_TRUE(local.add_result(local.unit(0, i), std::move(r)));
  }
  for (uint32_t i : {2u, 0u, 1u}) {  // (another order)
    UnitResult r;
    r.splats.reset(farm.frame().window);
    r.records = grid_records(photons_of(i));
    std::string error;
    ASSERT_TRUE(farm.check_records(farm.unit(0, i), r.records, error)) << error;
    ASSERT_TRUE(farm.add_result(farm.unit(0, i), std::move(r)));
  }
  const auto rendered = local.take_artifact(), stored = farm.take_artifact();
  ASSERT_TRUE(rendered && stored);
  EXPECT_NE(dynamic_cast<const PointRecordsArtifact*>(stored->artifact.get()), nullptr) << "records, not a grid";
  std::string error;
  const auto decoded = decode_point_map(IntegratorType::Sppm, stored->artifact->encode(), error);
  ASSERT_TRUE(decoded) << error;
  const auto& a = static_cast<const PhotonMapArtifact*>(rendered->artifact.get())->grid();
  const auto& b = static_cast<const PhotonMapArtifact*>(decoded.get())->grid();
  EXPECT_EQ(a.max_radius(), b.max_radius());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.records().data(), b.records().data(), a.size() * sizeof(Photon)), 0);
  // A record that is not finite is refused where records arrive, and by decode.
  std::vector<Photon> bad = photons_of(0);
  bad[1].power[0] = std::nanf("");
  EXPECT_FALSE(check_point_records(IntegratorType::Sppm, grid_records(bad), error));
  EXPECT_FALSE(check_point_records(IntegratorType::Sppm, "12345", error)) << "not whole records";
  EXPECT_FALSE(decode_point_map(IntegratorType::Sppm, PointRecordsArtifact(0.25f, {grid_records(bad)}).encode(), error));
}

// Only each tile's latest per-pixel state is kept; a checkpoint restores it for the next gather.
TEST(PassSequencer, OnlyATilesLatestStateIsKeptAndARestoreSetsIt) {
  PassProgram p = photon_program(3, 60);
  p.paths_per_unit = 60;
  PassSequencer seq(p, test::toy_frame(8), std::make_unique<GridBuilder<Photon>>([](uint32_t) { return 0.5f; }));
  auto run_pass = [&](uint32_t k) {
    UnitResult photons;
    photons.splats.reset(seq.frame().window);
    ASSERT_TRUE(seq.add_result(seq.unit(2 * k, 0), std::move(photons)));
    (void)seq.take_artifact();
    seq.artifact_stored(k, "h" + std::to_string(k));
    for (uint32_t t = 0; t < seq.num_tiles(); ++t) {
      UnitResult gathered;
      gathered.tile.reset(seq.tiles()[t]);
      gathered.tile_state = "pass " + std::to_string(k) + " tile " + std::to_string(t);
      ASSERT_TRUE(seq.add_result(seq.unit(2 * k + 1, t), std::move(gathered)));
    }
  };
  run_pass(0);
  run_pass(1);
  EXPECT_EQ(seq.tile_state(1, 4), "pass 1 tile 1") << "the latest Tile pass before pass 4";
  EXPECT_EQ(seq.tile_state(1, 3), "") << "pass 0's gather's, spent by pass 1's";
  seq.restore_tile_state(1, 4, "restored");
  EXPECT_EQ(*seq.work(seq.unit(5, 1)).tile_state, "restored");
}

}  // namespace
}  // namespace tessera
