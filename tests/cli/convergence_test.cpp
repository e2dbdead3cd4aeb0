// `tessera bench convergence`'s pieces on known inputs (relMSE, its trimmed form, the mean ratio,
// time to target, CSV, SVG), and the command in-process on a tiny scene against a reference
// written by the test.
#include "tessera/cli/commands.h"
#include "tessera/cli/convergence.h"
#include "tessera/image/image.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace tessera {
namespace {

using cli::ConvergencePoint;

Image filled(int w, int h, float v) {
  Image img(w, h, 3);
  std::fill(img.data(), img.data() + img.num_pixels() * 3, v);
  return img;
}

TEST(Convergence, RelMseTrimAndMeanRatioOnKnownImages) {
  // 40 x 25 = 1000 pixels of reference 1; the image is 1.1 everywhere but one pixel at 11.
  Image ref = filled(40, 25, 1.f);
  Image img = filled(40, 25, 1.1f);
  for (int c = 0; c < 3; ++c) img.at(7, 3, c) = 11.f;
  cli::ErrorMetrics m = cli::measure_error(img, ref);
  const double small = 0.01 / 1.01, big = 100.0 / 1.01;  // (x - 1)^2 / (1 + 0.01), in float below
  EXPECT_NEAR(m.rel_mse, (999 * small + big) / 1000, 1e-5);
  // 0.1% of 1000 pixels: exactly the one outlier is dropped.
  EXPECT_NEAR(m.rel_mse_trim, small, 1e-6);
  EXPECT_NEAR(m.mse, (999 * 0.01 + 100) / 1000, 1e-5);
  EXPECT_NEAR(m.mean_ratio, (999 * 1.1 + 11) / 1000, 1e-5);
  // Below 1000 pixels nothing is trimmed: the trimmed value equals the plain one.
  cli::ErrorMetrics few = cli::measure_error(filled(10, 10, 2.f), filled(10, 10, 1.f));
  EXPECT_NEAR(few.rel_mse_trim, few.rel_mse, 1e-12);
  EXPECT_NEAR(few.rel_mse, 1 / 1.01, 1e-6);
  EXPECT_NEAR(few.mean_ratio, 2.0, 1e-12);
  // Identical images: zero error, ratio one.
  cli::ErrorMetrics same = cli::measure_error(ref, ref);
  EXPECT_EQ(same.rel_mse, 0.0);
  EXPECT_EQ(same.rel_mse_trim, 0.0);
  EXPECT_EQ(same.mean_ratio, 1.0);
  EXPECT_THROW(cli::measure_error(filled(4, 4, 1.f), filled(4, 5, 1.f)), std::invalid_argument);
}

ConvergencePoint point(const std::string& strategy, int spp, double seconds, double rel_mse) {
  ConvergencePoint p;
  p.strategy = strategy;
  p.spp = spp;
  p.seconds = seconds;
  p.error.rel_mse = rel_mse;
  return p;
}

TEST(Convergence, TimeToTargetInterpolatesLogLog) {
  // relMSE = 0.1 / seconds: 1 s -> 0.1, 10 s -> 0.01, 100 s -> 0.001.
  std::vector<ConvergencePoint> pts = {point("mis", 1, 0.5, 0.2), point("mis", 2, 4, 0.025),
                                       point("mis", 4, 40, 0.0025)};
  cli::TimeToTarget t = cli::time_to_target(pts, 0.01);
  ASSERT_TRUE(t.reached);
  EXPECT_FALSE(t.at_first_budget);
  EXPECT_NEAR(t.seconds, 10.0, 1e-9);
  // Not reached within the budgets.
  EXPECT_FALSE(cli::time_to_target(pts, 0.001).reached);
  // Reached at the first budget: that budget's time, flagged as an upper bound.
  cli::TimeToTarget first = cli::time_to_target(pts, 0.5);
  EXPECT_TRUE(first.reached && first.at_first_budget);
  EXPECT_EQ(first.seconds, 0.5);
  // Not monotonic: the first crossing counts (between 1 and 2 here, log-log midpoint).
  std::vector<ConvergencePoint> bumpy = {point("nee", 1, 1, 0.1), point("nee", 2, 4, 0.001),
                                         point("nee", 4, 8, 0.5)};
  EXPECT_NEAR(cli::time_to_target(bumpy, 0.01).seconds, 2.0, 1e-9);
  EXPECT_FALSE(cli::time_to_target({}, 0.01).reached);
}

TEST(Convergence, CsvHasTheHeaderAndOneRowPerPoint) {
  std::vector<ConvergencePoint> pts = {point("bsdf", 1, 0.25, 0.5), point("nee", 2, 0.5, 0.125)};
  pts[0].noise_estimate = HUGE_VAL;
  pts[1].error.mean_ratio = 0.98;
  std::ostringstream out;
  cli::write_convergence_csv(out, pts);
  EXPECT_EQ(out.str(),
            "strategy,spp,seconds,relmse,relmse_trim,mse,mean_ratio,noise_estimate\n"
            "bsdf,1,0.250000,0.5,0,0,0,inf\n"
            "nee,2,0.500000,0.125,0,0,0.98,0\n");
}

TEST(Convergence, SvgHasBothPanelsAPolylinePerStrategyAndDecadeTicks) {
  std::vector<ConvergencePoint> pts = {point("mis", 1, 0.02, 0.3), point("mis", 4, 0.08, 0.04),
                                       point("bsdf", 1, 0.015, 0.9), point("bsdf", 4, 0.06, 0.2),
                                       point("bsdf", 16, 0.0, 0.05)};  // zero seconds: left out
  std::string svg = cli::convergence_svg(pts, "a <title> & more");
  auto count = [&](const std::string& s) {
    size_t n = 0;
    for (size_t pos = svg.find(s); pos != std::string::npos; pos = svg.find(s, pos + 1)) ++n;
    return n;
  };
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(count("<polyline"), 4u);  // 2 strategies x 2 panels
  // Markers: mis 2 + 2, bsdf 2 (time panel) + 3 (spp panel).
  EXPECT_EQ(count("<circle"), 9u);
  EXPECT_NE(svg.find("a &lt;title&gt; &amp; more"), std::string::npos);
  EXPECT_NE(svg.find("render time (s)"), std::string::npos);
  EXPECT_NE(svg.find("samples per pixel"), std::string::npos);
  // Time axis spans 10^-2..10^-1 and spp 10^0..10^2; relMSE 10^-2..10^0 on both panels.
  EXPECT_NE(svg.find(">10<tspan dy=\"-5\" font-size=\"8\">-2</tspan>"), std::string::npos);
  EXPECT_NE(svg.find(">10<tspan dy=\"-5\" font-size=\"8\">2</tspan>"), std::string::npos);
  EXPECT_EQ(count("font-size=\"8\">0</tspan>"), 2u + 1u);  // relMSE 10^0 twice, spp 10^0 once
  // Nothing plottable still gives a well-formed (empty) chart.
  std::string empty = cli::convergence_svg({}, "none");
  EXPECT_NE(empty.find("</svg>"), std::string::npos);
}

// The command end to end on a 16x8 plane: the reference is a 64-spp render of the same scene.
TEST(Convergence, CommandWritesCsvAndPlotAndChecksTheReferenceSize) {
  test::TempDir dir;
  std::string scene = dir.write("s.xml", R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="8"/></film>
  </sensor>
  <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="1.5" z="1"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
</scene>)");
  auto run = [](std::vector<std::string> args) {
    args.insert(args.begin(), "tessera");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    return cli::main_entry(int(argv.size()), argv.data());
  };
  const std::string ref = (dir.path / "ref.exr").string();
  ASSERT_EQ(run({"render", scene, "-o", ref, "--spp", "64", "-q"}), 0);
  const std::string csv = (dir.path / "out/c.csv").string(), svg = (dir.path / "out/c.svg").string();
  ASSERT_EQ(run({"bench", "convergence", scene, "--reference", ref, "--spp", "1,2,4", "--strategy", "bsdf,nee,mis",
                 "--csv", csv, "--plot", svg, "--threads", "1"}),
            0);
  std::ifstream in(csv);
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(in, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 10u);
  EXPECT_EQ(lines[0], "strategy,spp,seconds,relmse,relmse_trim,mse,mean_ratio,noise_estimate");
  EXPECT_EQ(lines[1].rfind("bsdf,1,", 0), 0u);
  EXPECT_EQ(lines[6].rfind("nee,4,", 0), 0u);
  EXPECT_EQ(lines[9].rfind("mis,4,", 0), 0u);
  EXPECT_TRUE(std::filesystem::exists(svg));
  // A reference of another size is an error, with --width/--height and without.
  EXPECT_EQ(run({"bench", "convergence", scene, "--reference", ref, "--spp", "1", "--width", "8", "--height", "8"}), 1);
  const std::string small = (dir.path / "small.exr").string();
  ASSERT_EQ(run({"render", scene, "-o", small, "--spp", "1", "--width", "8", "--height", "4", "-q"}), 0);
  EXPECT_EQ(run({"bench", "convergence", scene, "--reference", small, "--spp", "1"}), 1);
  EXPECT_EQ(run({"bench", "convergence", scene, "--reference", small, "--spp", "1", "--width", "8", "--height", "4"}), 0);
  // An unknown strategy is refused by the parser.
  EXPECT_NE(run({"bench", "convergence", scene, "--reference", ref, "--strategy", "bidir"}), 0);
}

}  // namespace
}  // namespace tessera
