#include "tessera/sequence/pass_program.h"

#include <algorithm>

namespace tessera {

const char* unit_kind_name(UnitKind kind) { return kind == UnitKind::Tile ? "tile" : "paths"; }

const char* film_combine_name(FilmCombine combine) {
  return combine == FilmCombine::Sum ? "sum" : "inverse_variance";
}

namespace {

std::string pass_error(const PassProgram& program, size_t p, const std::vector<bool>& used_before) {
  const PassSpec& pass = program.passes[p];
  const std::string where = "pass " + std::to_string(p) + ": ";
  if (pass.film != kNoFilm && (pass.film < 0 || pass.film >= program.films)) return where + "no such film";
  if ((pass.adaptive || pass.may_stop) && !pass.barrier) return where + "decides at no barrier";
  if (pass.kind == UnitKind::Paths && (pass.adaptive || pass.tile_state))
    return where + "a Paths pass has no per-pixel counts or state";
  if (pass.tile_state && std::none_of(program.passes.begin(), program.passes.begin() + std::ptrdiff_t(p),
                                      [](const PassSpec& q) { return q.kind == UnitKind::Tile; }))
    return where + "its per-pixel state comes from a Tile pass before it";
  if (pass.photons > 0 && (pass.kind != UnitKind::Paths || pass.same_samples || pass.samples != 0))
    return where + "a photon pass is a Paths pass of no sample indices";
  auto same_tile = [&](size_t q) {
    return q < program.passes.size() && program.passes[q].kind == UnitKind::Tile &&
           program.passes[q].sample_begin == pass.sample_begin && program.passes[q].samples == pass.samples;
  };
  if (pass.same_samples && (pass.kind != UnitKind::Paths || !((p > 0 && same_tile(p - 1)) || same_tile(p + 1))))
    return where + "traces the samples of a Tile pass just before or after it, which it does not follow or precede";
  if (pass.adaptive && p == 0) return where + "the first pass has no film to adapt to";
  if (pass.uses && *pass.uses > 0 && !used_before[*pass.uses] && !pass.barrier)
    return where + "renders with a new artifact without waiting for it (a barrier)";
  if (pass.feeds && pass.uses && *pass.feeds <= *pass.uses) return where + "feeds an artifact it renders with";
  return {};
}

}  // namespace

std::string program_error(const PassProgram& program) {
  if (program.films < 1) return "a program has at least one film";
  if (program.combine == FilmCombine::Sum && program.films != 1) return "the Sum rule combines exactly one film";
  if (program.paths_per_unit == 0) return "paths_per_unit is 0";
  uint32_t max_artifact = 0;
  for (const PassSpec& pass : program.passes) {
    max_artifact = std::max(max_artifact, pass.uses.value_or(0));
    max_artifact = std::max(max_artifact, pass.feeds.value_or(0));
  }
  uint32_t next_sample = 0;  // the passes take the sample indices 0 .. spp-1 in order
  for (size_t p = 0; p < program.passes.size(); ++p) {
    if (program.passes[p].kind == UnitKind::Paths && (program.passes[p].same_samples || program.passes[p].photons > 0))
      continue;  // (pass_error)
    if (program.passes[p].sample_begin != next_sample || program.passes[p].samples == 0)
      return "pass " + std::to_string(p) + ": its samples do not follow the pass before's";
    next_sample += program.passes[p].samples;
  }
  if (next_sample != program.spp) return "the passes' samples do not add up to spp";
  std::vector<bool> used_before(size_t(max_artifact) + 1, false);
  for (size_t p = 0; p < program.passes.size(); ++p) {
    if (std::string e = pass_error(program, p, used_before); !e.empty()) return e;
    if (program.passes[p].uses) used_before[*program.passes[p].uses] = true;
    // A pixel's adaptive samples keep consecutive indices only if no uniform pass follows.
    if (p > 0 && program.passes[p - 1].adaptive && !program.passes[p].adaptive)
      return "pass " + std::to_string(p) + ": every pass after an adaptive one is adaptive";
  }
  return {};
}

}  // namespace tessera
