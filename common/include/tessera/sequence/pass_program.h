// A render's passes, described once: what each pass's units are, what their results cover, where
// a pass must wait (a barrier) and what is decided there, which artifact it renders with and which
// it trains, and which film it goes into. PassSequencer (pass_sequencer.h) runs a program the same
// way for `tessera render` and for the farm's coordinator; a technique only writes its program.
#pragma once

#include "tessera/render/adaptive.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

/// How a pass is cut into units of work.
enum class UnitKind : uint8_t {
  /// One unit per tile of the window (make_tiles): samples [sample_begin, sample_begin + samples)
  /// of each of its pixels (or, in an adaptive pass, the counts decided for them). Its result
  /// covers its tile: a FilmTile of pixel sums.
  Tile,
  /// Ranges of the pass's light paths (or photons), `paths_per_unit` each: window pixels x samples
  /// paths in all, one per pixel sample as a light tracer traces them. Not tied to pixels: its
  /// result covers the whole window (SplatSums: what its paths added to which pixels).
  Paths,
};
const char* unit_kind_name(UnitKind kind);

/// How a render's films become its image (FilmAssembler::image).
enum class FilmCombine : uint8_t {
  /// One film (film 0): every sample that enters it, with weight 1.
  Sum,
  /// One film per iteration: each film's image weighted by the inverse of its estimated relMSE
  /// (noise_estimate.h), as Müller (2019) combines guiding's iterations; a film without an
  /// estimate (fewer than 2 samples a pixel) weighs nothing unless no film has one, when all
  /// weigh the same.
  InverseVariance,
};
const char* film_combine_name(FilmCombine combine);

/// A pass that enters no film (a guide's training passes when the image discards them).
inline constexpr int kNoFilm = -1;

struct PassSpec {
  UnitKind kind = UnitKind::Tile;
  /// The pass's sample indices per pixel: [sample_begin, sample_begin + samples). A Paths pass
  /// traces `samples` paths per window pixel, numbered from sample_begin x window pixels.
  uint32_t sample_begin = 0, samples = 0;
  /// Opens only once every earlier pass is complete, so that what is decided here (a stop at the
  /// target error, adaptive counts, an artifact) depends on exactly those passes' results.
  bool barrier = false;
  /// (Tile, barrier) Its per-pixel sample counts are decided at its barrier from the film
  /// (adaptive.h); each unit carries its tile's counts.
  bool adaptive = false;
  /// (barrier) The render stops here when the film's estimated relMSE is at most the target.
  bool may_stop = false;
  /// The film its results enter (0 .. films-1), or kNoFilm.
  int film = 0;
  /// The artifact iteration its units render with (see ArtifactBuilder), if any.
  std::optional<uint32_t> uses = std::nullopt;
  /// The artifact iteration its units' records go into, if any: made at the barrier of the first
  /// pass that uses it, from the iteration before and every record of the passes that feed it.
  std::optional<uint32_t> feeds = std::nullopt;
  /// (Tile) Unit (p, t) starts from the per-pixel state that unit t of the latest Tile pass before
  /// it left (a photon mapper's radii and counts): it is ready once that unit is done.
  bool tile_state = false;
  /// (Paths) Traces the light subpaths of the pixel samples of the Tile pass just before it, or
  /// just after it (vcm's light vertices, which that pass merges with) (the same sample_begin and
  /// samples; path k is sample k / window pixels of window pixel k mod window
  /// pixels, row-major): a bidirectional method's light tracing. It takes no sample indices of its
  /// own, so the passes' samples still add up to spp.
  bool same_samples = false;
  /// (Paths) > 0: a photon pass of this many photons, numbered from 0 within the pass (a photon
  /// mapper's, sequence/photon_program.h). It takes no sample indices of its own: sample_begin
  /// names the pass (the sample index of the Tile pass that gathers its photons), samples is 0.
  uint64_t photons = 0;
  bool operator==(const PassSpec&) const = default;
};

/// The paths a Paths pass traces: its photons, or `samples` per pixel of a window of
/// `window_pixels`.
inline uint64_t pass_paths(const PassSpec& pass, uint64_t window_pixels) {
  return pass.photons > 0 ? pass.photons : window_pixels * pass.samples;
}

struct PassProgram {
  std::vector<PassSpec> passes;
  uint32_t spp = 0;  // samples per pixel over all passes (a Paths pass's paths per pixel count)
  int films = 1;
  FilmCombine combine = FilmCombine::Sum;
  /// Paths per unit of a Paths pass (the last unit of a pass takes the remainder).
  uint64_t paths_per_unit = uint64_t(1) << 16;
  /// > 0: the estimate a `may_stop` barrier stops at.
  double target_error = 0;
  AdaptiveSettings adaptive_settings;
};

/// Checks a program's consistency (films, barriers before decisions, artifacts made before they
/// are used); an empty string when it is sound, else what is wrong.
std::string program_error(const PassProgram& program);

}  // namespace tessera
