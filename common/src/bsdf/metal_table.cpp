// Mitsuba's named conductors as linear-sRGB complex IORs eta + i k.
//
// Provenance: Mitsuba 0.6 ships spectral data/ior/<name>.eta.spd and <name>.k.spd (Palik's Handbook
// of Optical Constants, via Mitsuba). The RGB values below are the reduction of those spectra that
// Tungsten publishes (tunabrain/tungsten, src/core/bsdfs/ComplexIorData.hpp): each spectrum
// integrated against the CIE 1931 2-degree matching functions over the visible range, normalised by
// the integral of y-bar, and taken to linear sRGB (BT.709 primaries, D65) -- the same reduction as
// Mitsuba's RGB mode and tessera's spectrum_to_rgb (scene/spectrum.cpp). Cross-check: Mitsuba's
// Cu.eta.spd / Cu.k.spd through spectrum_to_rgb give eta (0.20098, 0.92376, 1.10222) and
// k (3.91326, 2.45304, 2.14210), within 0.3% of the entry below. Values rounded to 6 digits;
// the few tiny negative lobes the XYZ->RGB matrix produces (AlAs, AlSb, SiC, TiO2: |v| < 0.05) are
// clamped to 0 as spectrum_to_rgb does. The *_palik variants Mitsuba also ships are not listed
// (identical or near-identical data); `none` is Mitsuba's perfect mirror (eta 0, k 1: F = 1).
#include "tessera/bsdf/conductor.h"

#include <string_view>

namespace tessera {
namespace {

struct MetalEntry {
  std::string_view name;
  Rgb eta;
  Rgb k;
};

// clang-format off
const MetalEntry kMetals[] = {
    {"a-C", {2.9441f, 2.22715f, 1.96817f}, {0.887433f, 0.799322f, 0.815286f}},
    {"Ag", {0.155265f, 0.116723f, 0.138381f}, {4.82834f, 3.12225f, 2.14695f}},
    {"Al", {1.65746f, 0.880369f, 0.521229f}, {9.22387f, 6.26952f, 4.837f}},
    {"AlAs", {3.6051f, 3.23294f, 2.21756f}, {0.000667025f, 0.f, 0.00742612f}},
    {"AlSb", {0.f, 4.14275f, 4.66977f}, {0.f, 0.0937665f, 1.30074f}},
    {"Au", {0.143119f, 0.374957f, 1.44248f}, {3.98316f, 2.38572f, 1.60322f}},
    {"Be", {4.18506f, 3.18506f, 2.78409f}, {3.83544f, 3.01013f, 2.86901f}},
    {"Cr", {4.36968f, 2.9167f, 1.6547f}, {5.20643f, 4.23136f, 3.75495f}},
    {"CsI", {2.1449f, 1.70232f, 1.66242f}, {0.f, 0.f, 0.f}},
    {"Cu", {0.200438f, 0.924033f, 1.10221f}, {3.91295f, 2.45285f, 2.14219f}},
    {"Cu2O", {3.54928f, 2.95206f, 2.73692f}, {0.113218f, 0.194666f, 0.600168f}},
    {"CuO", {3.24538f, 2.44963f, 2.19741f}, {0.520274f, 0.570737f, 0.717225f}},
    {"d-C", {2.71125f, 2.31858f, 2.22886f}, {0.f, 0.f, 0.f}},
    {"Hg", {2.39893f, 1.44003f, 0.909551f}, {6.32763f, 4.37194f, 3.42179f}},
    {"HgTe", {4.77953f, 3.231f, 2.66003f}, {1.63198f, 1.58082f, 1.72958f}},
    {"Ir", {3.08641f, 2.08219f, 1.61789f}, {5.59215f, 4.06718f, 3.26726f}},
    {"K", {0.0640493f, 0.0464101f, 0.0381842f}, {2.10422f, 1.34894f, 0.913211f}},
    {"Li", {0.265787f, 0.19561f, 0.22092f}, {3.54017f, 2.31113f, 1.66859f}},
    {"MgO", {2.08959f, 1.65072f, 1.59488f}, {0.f, 0.f, 0.f}},
    {"Mo", {4.4837f, 3.52546f, 2.77608f}, {4.11113f, 3.42087f, 3.1506f}},
    {"Na_palik", {0.0602665f, 0.0561412f, 0.0619909f}, {3.17929f, 2.11248f, 1.57909f}},
    {"Nb", {3.42014f, 2.79019f, 2.39559f}, {3.44138f, 2.73764f, 2.57991f}},
    {"Ni_palik", {2.36728f, 1.66336f, 1.46706f}, {4.49883f, 3.05016f, 2.34543f}},
    {"Rh", {2.5858f, 1.86019f, 1.55443f}, {6.78229f, 4.70295f, 3.97609f}},
    {"Se", {4.05926f, 2.84269f, 2.82076f}, {0.754379f, 0.638515f, 0.521587f}},
    {"Se-e", {5.72427f, 4.1654f, 4.08161f}, {0.871375f, 1.10528f, 1.56478f}},
    {"SiC", {3.17235f, 2.52597f, 2.47936f}, {7.284e-07f, 0.f, 1.0015e-05f}},
    {"SnTe", {4.52519f, 1.98115f, 1.28168f}, {0.f, 0.f, 0.f}},
    {"Ta", {2.06258f, 2.39309f, 2.62807f}, {2.40805f, 1.74137f, 1.94704f}},
    {"Te", {7.39084f, 4.4821f, 2.63707f}, {3.25614f, 3.52739f, 3.29217f}},
    {"Te-e", {7.50904f, 4.29646f, 2.36987f}, {5.58421f, 4.94762f, 3.99751f}},
    {"ThF4", {1.83072f, 1.44223f, 1.38765f}, {0.f, 0.f, 0.f}},
    {"TiC", {3.70047f, 2.83744f, 2.5823f}, {3.26569f, 2.35156f, 2.17279f}},
    {"TiN", {1.64847f, 1.15045f, 1.37978f}, {3.36846f, 1.94349f, 1.10201f}},
    {"TiO2", {3.45662f, 2.80171f, 2.90515f}, {0.000102666f, 0.f, 0.00063569f}},
    {"TiO2-e", {3.10656f, 2.51316f, 2.58238f}, {2.89537e-05f, 0.f, 0.000177556f}},
    {"VC", {3.65757f, 2.75273f, 2.53268f}, {3.06835f, 2.19867f, 1.96318f}},
    {"VN", {2.8656f, 2.11918f, 1.94008f}, {3.03233f, 2.05611f, 1.61629f}},
    {"V_palik", {4.27751f, 3.51315f, 2.76113f}, {3.49118f, 2.88936f, 3.1117f}},
    {"W", {4.3707f, 3.3003f, 2.99827f}, {3.50068f, 2.60487f, 2.27319f}},
    {"none", {0.f, 0.f, 0.f}, {1.f, 1.f, 1.f}},
};
// clang-format on

}  // namespace

std::optional<ConductorIor> lookup_metal(std::string_view name) {
  for (const MetalEntry& e : kMetals)
    if (e.name == name) return ConductorIor{e.eta, e.k};
  return std::nullopt;
}

std::string known_metal_names() {
  std::string out;
  for (const MetalEntry& e : kMetals) {
    if (!out.empty()) out += ", ";
    out += e.name;
  }
  return out;
}

}  // namespace tessera
