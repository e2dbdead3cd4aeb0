// The `guided_path` integrator of Müller's Mitsuba 0.6 plugin ("Practical Path Guiding", 2017, with
// the 2019 notes' options): the path tracer with path guiding on, its parameters mapped onto
// GuidingSettings. Budgets that depend on time are refused: the image would depend on the machine.
#include "builder_internal.h"

#include <initializer_list>
#include <string>

namespace tessera::detail {

// Scenes for the 0.6 plugins are Mitsuba 0.x files, whose camelCase names reach us as snake_case
// (sTreeThreshold as s_tree_threshold); a 2.x/3.x file keeps the name as written.
std::string name_in(const SceneNode& node, const std::string& snake, const std::string& camel) {
  return node.peek(snake) || !node.peek(camel) ? snake : camel;
}

namespace {

/// A string parameter that must be one of `allowed`.
std::string choice(const SceneNode& node, const std::string& name, const std::string& def,
                   std::initializer_list<const char*> allowed) {
  const std::string v = node.get_string(name, def);
  std::string list;
  for (const char* a : allowed) {
    if (v == a) return v;
    list += std::string(list.empty() ? "" : ", ") + a;
  }
  throw SceneError(node.loc_of(name), "'" + name + "' of " + node.describe() + " must be one of " + list + ", got '" + v + "'");
}

double number_in(const SceneNode& node, const std::string& name, double def, double lo, double hi, bool open_lo) {
  const double v = node.get_float(name, float(def));
  if (!(open_lo ? v > lo : v >= lo) || !(v <= hi))
    throw SceneError(node.loc_of(name), "'" + name + "' of " + node.describe() + " must be in " + (open_lo ? "(" : "[") +
                                            std::to_string(lo) + ", " + std::to_string(hi) + "], got " + std::to_string(v));
  return v;
}

/// budgetType and budget: samples per pixel, or an error for seconds (also the plugin's default).
void read_budget(BuildState& st, const SceneNode& node) {
  const std::string type_name = name_in(node, "budget_type", "budgetType");
  if (!node.peek(type_name))
    throw SceneError(node.loc, node.describe() + ": the plugin's default budget is 300 seconds, which would make the image "
                                                 "depend on the machine; set budgetType to \"spp\" and budget to the samples per pixel");
  if (choice(node, type_name, "seconds", {"spp", "seconds"}) == "seconds")
    throw SceneError(node.loc_of(type_name), node.describe() + ": budgetType \"seconds\" would make the image depend on the "
                                                               "machine; use \"spp\" (budget = samples per pixel)");
  if (node.peek("budget")) st.spp_budget = int(number_in(node, "budget", 1, 1, double(1 << 24), false));
}

void read_combination(BuildState& st, const SceneNode& node, GuidingSettings& g) {
  const std::string name = name_in(node, "sample_combination", "sampleCombination");
  const std::string tessera_default = guide_combination_name(g.combination);
  if (!node.peek(name)) {
    st.ctx.note(node.loc, node.describe() + ": no sampleCombination (the plugin's default is \"automatic\"); rendered as \"" +
                              tessera_default + "\"");
    return;
  }
  const std::string v = choice(node, name, "automatic", {"discard", "automatic", "inversevar"});
  if (v == "automatic")
    st.ctx.unsupported(node.loc_of(name), "sampleCombination \"automatic\" of " + node.describe(), tessera_default);
  else
    g.combination = v == "discard" ? GuideCombination::Discard : GuideCombination::InverseVariance;
}

void read_filters_and_loss(BuildState& st, const SceneNode& node, GuidingSettings& g) {
  const std::string spatial = name_in(node, "spatial_filter", "spatialFilter");
  const std::string v = choice(node, spatial, "nearest", {"nearest", "stochastic", "box"});
  // (Müller's deterministic box splats every record into each leaf its box overlaps.)
  if (v == "box") st.ctx.unsupported(node.loc_of(spatial), "spatialFilter \"box\" of " + node.describe(), "stochastic");
  g.spatial_filter = v == "nearest" ? SpatialFilter::Nearest : SpatialFilter::Stochastic;
  const std::string directional = name_in(node, "directional_filter", "directionalFilter");
  (void)parse_directional_filter(choice(node, directional, "nearest", {"nearest", "box"}), g.directional_filter);
  const std::string loss = name_in(node, "bsdf_sampling_fraction_loss", "bsdfSamplingFractionLoss");
  const std::string l = choice(node, loss, "none", {"none", "kl", "var"});
  if (l == "var") st.ctx.unsupported(node.loc_of(loss), "bsdfSamplingFractionLoss \"var\" of " + node.describe(), "kl");
  g.learn_bsdf_fraction = l != "none";
}

void read_notes(BuildState& st, const SceneNode& node) {
  if (choice(node, "nee", "never", {"never", "kickstart", "always"}) != "always")
    st.ctx.note(node.loc_of("nee"), node.describe() + ": Tessera always uses next-event estimation where it can "
                                                    "(the same expected image)");
  const std::string per_pass = name_in(node, "spp_per_pass", "sppPerPass");
  if (node.peek(per_pass) && node.get_int(per_pass, 4) > 0)
    st.ctx.note(node.loc_of(per_pass), node.describe() + ": sppPerPass ignored; training iterations are Tessera's passes "
                                                         "of 1, 2, 4, ... samples per pixel");
  const std::string dump = name_in(node, "dump_sdtree", "dumpSDTree");
  if (node.get_bool(dump, false)) st.ctx.unsupported(node.loc_of(dump), "dumpSDTree of " + node.describe(), "ignored");
}

}  // namespace

void read_guided_path(BuildState& st, const SceneNode& node) {
  GuidingSettings g;
  read_budget(st, node);
  read_combination(st, node, g);
  read_filters_and_loss(st, node, g);
  read_notes(st, node);
  // (Tessera's own: Müller's plugin always keeps paths with probability 0.99, "guided".)
  (void)parse_guide_roulette(choice(node, "roulette", guide_roulette_name(g.roulette), {"radiance", "throughput", "guided"}),
                             g.roulette);
  g.bsdf_fraction = float(number_in(node, name_in(node, "bsdf_sampling_fraction", "bsdfSamplingFraction"), 0.5, 0, 1, true));
  g.spatial_threshold = number_in(node, name_in(node, "s_tree_threshold", "sTreeThreshold"), 12000, 0, 1e9, true);
  g.directional_threshold = number_in(node, name_in(node, "d_tree_threshold", "dTreeThreshold"), 0.01, 0, 1, true);
  // (Tessera's own: guiding steps aside where the deciding iteration predicts less; 0 never.)
  g.min_gain = number_in(node, "min_gain", g.min_gain, 0, 1e6, false);
  const int64_t paths = node.get_int("gain_paths", int64_t(g.gain_paths));
  if (paths < 1)
    throw SceneError(node.loc_of("gain_paths"), "'gain_paths' of " + node.describe() + " must be at least 1, got " +
                                                    std::to_string(paths));
  g.gain_paths = uint64_t(paths);
  const std::string memory = name_in(node, "sd_tree_max_memory", "sdTreeMaxMemory");
  const int64_t mb = node.get_int(memory, -1);
  if (mb != -1 && (mb < 1 || mb > (int64_t(1) << 20)))
    throw SceneError(node.loc_of(memory), "'" + memory + "' of " + node.describe() + " must be -1 (Tessera's cap, " +
                                              std::to_string(g.max_bytes >> 20) + " MB) or in [1, 1048576] MB, got " +
                                              std::to_string(mb));
  if (mb > 0) g.max_bytes = size_t(mb) << 20;
  st.scene.integrator.guiding = g;
}

}  // namespace tessera::detail
