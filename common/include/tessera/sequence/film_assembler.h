// Results into films, in an order the program fixes, whatever order they arrive in.
//
// - A tile's results (FilmTile) enter their pass's film in pass order, one tile at a time: a
//   pixel's sums are (sums of pass 0) + (sums of pass 1) + ..., as film.h promises. A result that
//   arrives before an earlier pass of its tile is held until that one is in.
// - Paths units' results (SplatSums) are folded into their film's splat layer in (pass, unit)
//   order, each unit's splats in the order it made them; an early one is held likewise.
// - A pass with film kNoFilm enters nothing, but keeps its place in the order.
// - The image (FilmCombine, pass_program.h): each film's pixel is its mean plus its splat sum over
//   the light paths per pixel folded into it (a light tracer's splat scale); with Sum that is the
//   image, with InverseVariance the films' images are averaged with weights 1 / (relMSE + 1e-12),
//   relMSE the film's estimate (noise_estimate.h, each pixel's term clamped at 1), 0 for a film
//   without one (all equal when no film has one), summed in double and rounded once. The AOV
//   layers are the last film's (the one the last pass enters).
//
// Films are allocated on the first result (a queued farm job holds none) and can be released once
// the image is written. Not thread-safe: the caller serialises.
#pragma once

#include "tessera/image/image.h"
#include "tessera/render/film.h"
#include "tessera/render/noise_estimate.h"
#include "tessera/sequence/pass_program.h"
#include "tessera/sequence/splat_sums.h"

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

namespace tessera {

class FilmAssembler {
 public:
  FilmAssembler(const PassProgram& program, std::vector<TileRect> tiles, const TileRect& window, int full_width,
                int full_height, bool aovs);

  /// Tile `tile`'s result of Tile pass `pass` (each once).
  void add_tile(uint32_t pass, uint32_t tile, FilmTile&& result);
  /// Unit `index` of Paths pass `pass` (each once). Folded at once, or with fold_later() held for
  /// fold_splats().
  void add_splat(uint32_t pass, uint32_t index, SplatSums&& result);
  /// Splats are folded only by fold_splats(): a coordinator folds a unit a chunk at a time, taking
  /// its lock for each chunk rather than for a whole image-wide result.
  void fold_later() { fold_later_ = true; }
  /// Folds up to `max_splats` splats of the units next in order (a unit may be left part-folded,
  /// its rest folded next time); how many it folded. splats_ready() says whether more are.
  size_t fold_splats(size_t max_splats);
  /// Splats held, ready to fold or waiting for an earlier unit.
  bool splats_held() const { return !held_splats_.empty(); }
  /// Whether the next unit in order is held (fold_splats() has work).
  bool splats_ready() const { return held_splats_.count(next_splat_) > 0; }

  /// The tile's next pass to enter its film (passes before it are in; the number of passes once
  /// every one is).
  uint32_t next_pass(uint32_t tile) const { return next_[tile]; }
  /// Counts every change of the films' sums (a result entered or a tile restored).
  uint64_t changes() const { return changes_; }
  /// Counters of every result that entered.
  const RenderCounters& counters() const { return counters_; }

  bool allocated() const { return !films_.empty(); }
  bool released() const { return released_; }
  /// Frees the films (and held results) of a render whose image is written.
  void release();
  /// Film `f` (allocated()).
  const Film& film(int f) const { return *films_[size_t(f)]; }
  /// Moves film `f` out with its splats (a finished local render; the assembler is spent).
  Film take_film(int f);
  /// (InverseVariance) A film holding the image: each pixel's mean is image()'s bits, its
  /// variance of the mean the combination's (the weighted films' variances), over a count that
  /// is the largest power of two within its samples; the AOVs are the primary film's.
  Film combined_film() const;
  int primary_film() const { return primary_; }
  /// (InverseVariance) The films of the passes that use artifact `artifact` or a later one hold
  /// samples of one estimator (the technique stepped aside: Artifact::stepped_aside_from). They
  /// are weighed as one film: the sum of their weights, shared in proportion to their samples per
  /// pixel, rather than by each one's noisier estimate of its own variance.
  void set_alike_from(uint32_t artifact);

  /// The estimate of the image's relMSE (Sum: film 0's; InverseVariance: 1 / the sum of the films'
  /// weights); +inf before there is one.
  NoiseEstimate noise() const;
  /// The image by the program's rule (black before any result).
  Image image() const;
  /// Film `f`'s splat sums (3 per window pixel; empty before a splat arrived).
  const std::vector<double>& splats(int f) const { return splats_[size_t(f)]; }
  /// Film `f`'s own image (allocated()): its mean plus its splats over its light paths per pixel.
  Image film_image(int f) const;
  /// Rows [row_begin, row_end) of image() into `img` (the window's size): a large film converted a
  /// band at a time. With InverseVariance, the weights are those of the films at the call.
  void image_rows(Image& img, int row_begin, int row_end) const;
  /// Rows of an AOV layer (aov.h) of the primary film, as Film::aov_rows.
  void aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const;

  // Checkpoints (a coordinator stores a tile's sums in place of its results): the tile's region of
  // each film, the first with the counters of the passes in them, and back.
  std::vector<FilmTile> tile_regions(uint32_t tile) const;
  /// Rebuilding: the tile's sums in each film over every pass before `next_pass` (their results
  /// are then never added); adding them to zero films reproduces the sums bit for bit.
  void restore_tile(uint32_t tile, uint32_t next_pass, std::vector<FilmTile>&& sums);

 private:
  void allocate();
  void enter_tile(uint32_t pass, uint32_t tile, FilmTile& result);
  uint32_t next_tile_pass(uint32_t after) const;
  uint64_t unit_paths(uint32_t pass, uint32_t index) const;
  std::vector<double> weights() const;
  // The alike films' weights: their sum, in proportion to their passes' samples per pixel.
  void share_alike(std::vector<double>& w) const;
  void pixel_row(int f, int y, std::vector<float>& row) const;
  void combined_row(int y, const std::vector<double>& w, std::vector<float>& out) const;

  PassProgram program_;
  std::vector<TileRect> tiles_;
  TileRect window_;
  int full_width_, full_height_;
  bool aovs_;
  int primary_ = 0;
  int alike_from_ = -1;  // the first film of set_alike_from()'s, or none
  std::vector<std::unique_ptr<Film>> films_;
  std::vector<std::vector<double>> splats_;  // per film: 3 per pixel once a splat arrived
  std::vector<uint64_t> splat_paths_;        // per film: light paths folded into it
  std::vector<uint32_t> next_;               // per tile
  std::vector<RenderCounters> tile_counters_;  // per tile: of the passes in its film
  std::map<std::pair<uint32_t, uint32_t>, FilmTile> held_tiles_;    // by (pass, tile)
  std::map<std::pair<uint32_t, uint32_t>, SplatSums> held_splats_;  // by (pass, unit)
  std::pair<uint32_t, uint32_t> next_splat_;                         // (pass, unit) folded next
  size_t next_splat_entry_ = 0;                                      // of that unit, folded so far
  bool fold_later_ = false;
  RenderCounters counters_;
  uint64_t changes_ = 0;
  bool released_ = false;
};

}  // namespace tessera
