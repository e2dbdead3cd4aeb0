#include "tessera/farm/program_json.h"

#include "tessera/render/sppm.h"

namespace tessera {

using nlohmann::json;

namespace {

json pass_json(const PassSpec& p) {
  json j = {{"kind", unit_kind_name(p.kind)},
          {"sample_begin", p.sample_begin},
          {"samples", p.samples},
          {"barrier", p.barrier},
          {"adaptive", p.adaptive},
          {"may_stop", p.may_stop},
          {"film", p.film},
          {"uses", p.uses ? json(*p.uses) : json(nullptr)},
          {"feeds", p.feeds ? json(*p.feeds) : json(nullptr)},
          {"tile_state", p.tile_state},
          {"same_samples", p.same_samples}};
  if (p.photons > 0) j["photons"] = p.photons;  // (a photon pass's)
  return j;
}

std::optional<uint32_t> optional_u32(const json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<uint32_t>();
}

PassSpec pass_from_json(const json& j) {
  // (Plans stored before same_samples existed have the other ten; only a photon pass has photons.)
  const bool has_same = j.contains("same_samples"), has_photons = j.contains("photons");
  if (j.size() != 10u + has_same + has_photons) throw std::invalid_argument("a pass has exactly its eleven fields");
  PassSpec p;
  const std::string kind = j.at("kind").get<std::string>();
  if (kind != "tile" && kind != "paths") throw std::invalid_argument("pass kind '" + kind + "'");
  p.kind = kind == "tile" ? UnitKind::Tile : UnitKind::Paths;
  p.sample_begin = j.at("sample_begin").get<uint32_t>();
  p.samples = j.at("samples").get<uint32_t>();
  p.barrier = j.at("barrier").get<bool>();
  p.adaptive = j.at("adaptive").get<bool>();
  p.may_stop = j.at("may_stop").get<bool>();
  p.film = j.at("film").get<int>();
  p.uses = optional_u32(j.at("uses"));
  p.feeds = optional_u32(j.at("feeds"));
  p.tile_state = j.at("tile_state").get<bool>();
  p.same_samples = has_same && j.at("same_samples").get<bool>();
  if (has_photons) p.photons = j.at("photons").get<uint64_t>();
  if (has_photons && (p.photons == 0 || p.photons > kMaxPhotonsPerPass || p.kind != UnitKind::Paths))
    throw std::invalid_argument("a photon pass has 1 to " + std::to_string(kMaxPhotonsPerPass) + " photons");
  return p;
}

}  // namespace

json to_json(const PassProgram& program) {
  json passes = json::array();
  for (const PassSpec& p : program.passes) passes.push_back(pass_json(p));
  const AdaptiveSettings& a = program.adaptive_settings;
  return {{"spp", program.spp},
          {"films", program.films},
          {"combine", film_combine_name(program.combine)},
          {"paths_per_unit", program.paths_per_unit},
          {"target_error", program.target_error},
          {"adaptive", {{"min_samples", a.min_samples}, {"uniform_fraction", a.uniform_fraction}, {"max_factor", a.max_factor}}},
          {"passes", passes}};
}

bool program_from_json(const json& j, PassProgram& out, std::string& error) {
  try {
    if (!j.is_object() || j.size() != 7) throw std::invalid_argument("a program has exactly its seven fields");
    PassProgram p;
    p.spp = j.at("spp").get<uint32_t>();
    p.films = j.at("films").get<int>();
    const std::string combine = j.at("combine").get<std::string>();
    if (combine != film_combine_name(FilmCombine::Sum) && combine != film_combine_name(FilmCombine::InverseVariance))
      throw std::invalid_argument("film combination '" + combine + "'");
    p.combine = combine == film_combine_name(FilmCombine::Sum) ? FilmCombine::Sum : FilmCombine::InverseVariance;
    p.paths_per_unit = j.at("paths_per_unit").get<uint64_t>();
    p.target_error = j.at("target_error").get<double>();
    const json& a = j.at("adaptive");
    p.adaptive_settings = {a.at("min_samples").get<uint32_t>(), a.at("uniform_fraction").get<double>(),
                           a.at("max_factor").get<uint32_t>()};
    for (const json& pass : j.at("passes")) p.passes.push_back(pass_from_json(pass));
    if (std::string e = program_error(p); !e.empty()) throw std::invalid_argument(e);
    out = std::move(p);
    return true;
  } catch (const std::exception& e) {
    error = std::string("pass program: ") + e.what();
    return false;
  }
}

}  // namespace tessera
