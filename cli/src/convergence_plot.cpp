// The SVG of `tessera bench convergence` (convergence.h): written by hand, no plotting library.
#include "tessera/cli/convergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace tessera::cli {
namespace {

constexpr double kPanelW = 440, kPanelH = 340;
constexpr double kLeft = 64, kRight = 16, kTop = 34, kBottom = 48;  // plot area margins in a panel

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

const char* colour(const std::string& strategy, size_t index) {
  if (strategy == "mis") return "#1f77b4";
  if (strategy == "bsdf") return "#d62728";
  if (strategy == "nee") return "#2ca02c";
  static const char* others[] = {"#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f"};
  return others[index % 5];
}

bool plottable(double x, double y) { return x > 0 && y > 0 && std::isfinite(x) && std::isfinite(y); }

// Whole decades covering [lo, hi] (one decade at least).
void decades(double lo, double hi, int& d0, int& d1) {
  d0 = int(std::floor(std::log10(lo) + 1e-9));
  d1 = int(std::ceil(std::log10(hi) - 1e-9));
  if (d1 <= d0) d1 = d0 + 1;
}

struct Axis {
  int d0 = 0, d1 = 1;
  double pixel_lo = 0, pixel_hi = 1;  // screen coordinates of 10^d0 and 10^d1
  double map(double v) const {
    return pixel_lo + (std::log10(v) - d0) / double(d1 - d0) * (pixel_hi - pixel_lo);
  }
};

// "10" with the exponent raised.
std::string decade_label(int d, double x, double y, const char* anchor) {
  std::ostringstream s;
  s << "<text x=\"" << num(x) << "\" y=\"" << num(y) << "\" text-anchor=\"" << anchor
    << "\" font-size=\"11\">10<tspan dy=\"-5\" font-size=\"8\">" << d << "</tspan></text>\n";
  return s.str();
}

void panel(std::ostringstream& svg, const std::vector<ConvergencePoint>& points,
           const std::vector<std::string>& strategies, double ox, bool by_seconds) {
  auto xval = [&](const ConvergencePoint& p) { return by_seconds ? p.seconds : double(p.spp); };
  double xlo = HUGE_VAL, xhi = 0, ylo = HUGE_VAL, yhi = 0;
  for (const auto& p : points) {
    if (!plottable(xval(p), p.error.rel_mse)) continue;
    xlo = std::min(xlo, xval(p));
    xhi = std::max(xhi, xval(p));
    ylo = std::min(ylo, p.error.rel_mse);
    yhi = std::max(yhi, p.error.rel_mse);
  }
  if (!(xhi > 0)) xlo = 1, xhi = 10, ylo = 1e-3, yhi = 1;  // nothing to plot: empty axes
  Axis ax, ay;
  decades(xlo, xhi, ax.d0, ax.d1);
  decades(ylo, yhi, ay.d0, ay.d1);
  const double x0 = ox + kLeft, x1 = ox + kPanelW - kRight, y0 = kTop, y1 = kPanelH - kBottom;
  ax.pixel_lo = x0, ax.pixel_hi = x1;
  ay.pixel_lo = y1, ay.pixel_hi = y0;

  svg << "<g>\n<rect x=\"" << num(x0) << "\" y=\"" << num(y0) << "\" width=\"" << num(x1 - x0) << "\" height=\""
      << num(y1 - y0) << "\" fill=\"none\" stroke=\"#000\"/>\n";
  for (int d = ax.d0; d <= ax.d1; ++d) {
    double x = ax.map(std::pow(10.0, d));
    svg << "<line x1=\"" << num(x) << "\" y1=\"" << num(y0) << "\" x2=\"" << num(x) << "\" y2=\"" << num(y1)
        << "\" stroke=\"#ddd\"/>\n";
    svg << "<line x1=\"" << num(x) << "\" y1=\"" << num(y1) << "\" x2=\"" << num(x) << "\" y2=\"" << num(y1 + 5)
        << "\" stroke=\"#000\"/>\n";
    svg << decade_label(d, x, y1 + 19, "middle");
  }
  for (int d = ay.d0; d <= ay.d1; ++d) {
    double y = ay.map(std::pow(10.0, d));
    svg << "<line x1=\"" << num(x0) << "\" y1=\"" << num(y) << "\" x2=\"" << num(x1) << "\" y2=\"" << num(y)
        << "\" stroke=\"#ddd\"/>\n";
    svg << "<line x1=\"" << num(x0 - 5) << "\" y1=\"" << num(y) << "\" x2=\"" << num(x0) << "\" y2=\"" << num(y)
        << "\" stroke=\"#000\"/>\n";
    svg << decade_label(d, x0 - 8, y + 4, "end");
  }
  svg << "<text x=\"" << num((x0 + x1) / 2) << "\" y=\"" << num(kPanelH - 10) << "\" text-anchor=\"middle\" "
      << "font-size=\"12\">" << (by_seconds ? "render time (s)" : "samples per pixel") << "</text>\n";
  svg << "<text x=\"" << num(ox + 14) << "\" y=\"" << num((y0 + y1) / 2) << "\" text-anchor=\"middle\" "
      << "font-size=\"12\" transform=\"rotate(-90 " << num(ox + 14) << " " << num((y0 + y1) / 2)
      << ")\">relMSE</text>\n";

  for (size_t si = 0; si < strategies.size(); ++si) {
    std::ostringstream pts, marks;
    const char* c = colour(strategies[si], si);
    for (const auto& p : points) {
      if (p.strategy != strategies[si] || !plottable(xval(p), p.error.rel_mse)) continue;
      double x = ax.map(xval(p)), y = ay.map(p.error.rel_mse);
      pts << num(x) << "," << num(y) << " ";
      marks << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y) << "\" r=\"2.5\" fill=\"" << c << "\"/>\n";
    }
    svg << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\" points=\"" << pts.str() << "\"/>\n"
        << marks.str();
  }
  svg << "</g>\n";
}

}  // namespace

std::string convergence_svg(const std::vector<ConvergencePoint>& points, const std::string& title) {
  std::vector<std::string> strategies;
  for (const auto& p : points)
    if (std::find(strategies.begin(), strategies.end(), p.strategy) == strategies.end())
      strategies.push_back(p.strategy);

  std::ostringstream svg;
  const double width = 2 * kPanelW, height = kPanelH + 10;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width) << "\" height=\"" << num(height)
      << "\" viewBox=\"0 0 " << num(width) << " " << num(height) << "\" font-family=\"sans-serif\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n"
      << "<text x=\"" << num(width / 2) << "\" y=\"18\" text-anchor=\"middle\" font-size=\"14\">"
      << xml_escape(title) << "</text>\n";
  panel(svg, points, strategies, 0, true);
  panel(svg, points, strategies, kPanelW, false);
  // Legend inside the right panel's upper right corner (errors fall from upper left).
  double lx = 2 * kPanelW - kRight - 90, ly = kTop + 8;
  for (size_t si = 0; si < strategies.size(); ++si) {
    double y = ly + 16 * double(si);
    svg << "<line x1=\"" << num(lx) << "\" y1=\"" << num(y) << "\" x2=\"" << num(lx + 20) << "\" y2=\"" << num(y)
        << "\" stroke=\"" << colour(strategies[si], si) << "\" stroke-width=\"2\"/>\n"
        << "<text x=\"" << num(lx + 26) << "\" y=\"" << num(y + 4) << "\" font-size=\"11\">"
        << xml_escape(strategies[si]) << "</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace tessera::cli
