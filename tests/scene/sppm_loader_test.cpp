// The `sppm` integrator in scene files: Mitsuba 0.6's parameters (under either spelling in a 3.x
// file) map onto IntegratorSettings with 0.6's defaults, granularity gets a note, bad values name
// the file, line and parameter, a scene with media is rendered by volpath with a note, and
// --integrator sppm over a path tracer keeps its depths.
#include "tessera/render/sppm.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include "integrator_loading.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <string>

namespace tessera {
namespace {

using namespace tessera::test;

const IntegratorLoader load{"mem/sppm.xml"};

TEST(SppmLoader, MapsMitsuba06Parameters) {
  LoadResult r = load(R"(<integrator type="sppm">
<integer name="maxDepth" value="7"/>
<integer name="rrDepth" value="4"/>
<integer name="photonCount" value="50000"/>
<float name="initialRadius" value="0.25"/>
<float name="alpha" value="0.5"/>
<integer name="maxPasses" value="12"/>
<integer name="granularity" value="100000"/>
</integrator>)");
  const IntegratorSettings& s = r.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Sppm);
  EXPECT_EQ(s.max_depth, 7);
  EXPECT_EQ(s.rr_depth, 4);
  EXPECT_EQ(s.photon_count, 50000u);
  EXPECT_FLOAT_EQ(s.initial_radius, 0.25f);
  EXPECT_FLOAT_EQ(s.alpha, 0.5f);
  EXPECT_EQ(s.max_passes, 12);
  EXPECT_FALSE(s.photon_direct);  // (never read from files)
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_EQ(r.messages.size(), 1u);
  EXPECT_EQ(r.messages[0].level, LoadMessage::Level::Note);
  EXPECT_NE(r.messages[0].text.find("parameter 'granularity' of integrator 'sppm' only sets how Mitsuba schedules"),
            std::string::npos)
      << r.messages[0].text;
  EXPECT_EQ(r.messages[0].loc.line, 9);
  // The largest photon count a pass may have, and alpha's closed end.
  LoadResult cap = load("<integrator type=\"sppm\">\n<integer name=\"photonCount\" value=\"" +
                        std::to_string(kMaxPhotonsPerPass) + "\"/>\n<float name=\"alpha\" value=\"1\"/>\n</integrator>");
  EXPECT_EQ(cap.scene->integrator.photon_count, kMaxPhotonsPerPass);
  EXPECT_FLOAT_EQ(cap.scene->integrator.alpha, 1.f);
}

TEST(SppmLoader, DefaultsAndEitherSpellingInA3File) {
  LoadResult d = load("<integrator type=\"sppm\"/>");
  const IntegratorSettings& s = d.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Sppm);
  EXPECT_EQ(s.max_depth, -1);
  EXPECT_EQ(s.rr_depth, 3);  // Mitsuba 0.6 sppm's (path's is 5)
  EXPECT_EQ(s.photon_count, 250000u);
  EXPECT_FLOAT_EQ(s.initial_radius, 0.f);  // automatic
  EXPECT_FLOAT_EQ(s.alpha, 0.7f);
  EXPECT_EQ(s.max_passes, -1);
  EXPECT_TRUE(d.messages.empty());
  // rrDepth keeps its default when only maxDepth is given.
  EXPECT_EQ(load("<integrator type=\"sppm\"><integer name=\"maxDepth\" value=\"6\"/></integrator>").scene->integrator.rr_depth,
            3);
  // sppm is not a Mitsuba 3 plugin: a 3.x file may keep 0.6's names or use the snake_case ones.
  for (const bool camel : {true, false}) {
    auto name = [&](const char* c, const char* s) { return std::string(camel ? c : s); };
    LoadResult r = load("<integrator type=\"sppm\"><integer name=\"" + name("maxDepth", "max_depth") +
                            "\" value=\"4\"/><integer name=\"" + name("rrDepth", "rr_depth") +
                            "\" value=\"2\"/><integer name=\"" + name("photonCount", "photon_count") +
                            "\" value=\"1234\"/><float name=\"" + name("initialRadius", "initial_radius") +
                            "\" value=\"0.5\"/><float name=\"alpha\" value=\"0.9\"/><integer name=\"" +
                            name("maxPasses", "max_passes") + "\" value=\"3\"/><integer name=\"granularity\" value=\"7\"/></integrator>",
                        kPerspective, "3.0.0");
    const IntegratorSettings& t = r.scene->integrator;
    const std::string what = camel ? "camelCase" : "snake_case";
    EXPECT_EQ(t.type, IntegratorType::Sppm) << what;
    EXPECT_EQ(t.max_depth, 4) << what;
    EXPECT_EQ(t.rr_depth, 2) << what;
    EXPECT_EQ(t.photon_count, 1234u) << what;
    EXPECT_FLOAT_EQ(t.initial_radius, 0.5f) << what;
    EXPECT_FLOAT_EQ(t.alpha, 0.9f) << what;
    EXPECT_EQ(t.max_passes, 3) << what;
    EXPECT_TRUE(r.unsupported.empty()) << what;
    EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "parameter 'granularity' of integrator 'sppm'"), 1u) << what;
    EXPECT_EQ(r.messages.size(), 1u) << what;
  }
}

TEST(SppmLoader, BadValuesNameFileLineAndParameter) {
  auto error_of = [](const std::string& parameter) {
    return scene_error_of([&] { load("<integrator type=\"sppm\">\n<integer name=\"maxDepth\" value=\"5\"/>\n" + parameter + "\n</integrator>"); });
  };
  struct Case {
    const char* parameter;
    const char* names;  // the parameter, as the message names it
  };
  const Case cases[] = {
      {R"(<integer name="photonCount" value="0"/>)", "'photonCount' of integrator 'sppm' is 0"},
      {R"(<integer name="photonCount" value="-5"/>)", "'photonCount' of integrator 'sppm' is -5"},
      {R"(<float name="alpha" value="0"/>)", "'alpha' of integrator 'sppm' must be in (0"},
      {R"(<float name="alpha" value="1.5"/>)", "'alpha' of integrator 'sppm' must be in (0"},
      {R"(<float name="alpha" value="nan"/>)", "'alpha'"},
      {R"(<float name="initialRadius" value="-1"/>)", "'initialRadius' of integrator 'sppm' must be >= 0"},
      {R"(<integer name="maxPasses" value="-2"/>)", "of integrator 'sppm' must be in [-1, "},
      {R"(<integer name="rrDepth" value="0"/>)", "of integrator 'sppm' must be in [1, "},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.parameter);
    EXPECT_NE(e.find("mem/sppm.xml:4: "), std::string::npos) << c.parameter << ": " << e;
    EXPECT_NE(e.find(c.names), std::string::npos) << c.parameter << ": " << e;
  }
  // The parameter's name, in either spelling, for the integers read like path's.
  EXPECT_NE(error_of(R"(<integer name="maxPasses" value="-2"/>)").find("max_passes"), std::string::npos);
  // One photon more than a pass's photon map holds: the message names the cap.
  const std::string over = error_of("<integer name=\"photonCount\" value=\"" + std::to_string(kMaxPhotonsPerPass + 1) + "\"/>");
  EXPECT_NE(over.find("mem/sppm.xml:4: 'photonCount' of integrator 'sppm' is " + std::to_string(kMaxPhotonsPerPass + 1)),
            std::string::npos)
      << over;
  EXPECT_NE(over.find("holds 1 to " + std::to_string(kMaxPhotonsPerPass) + " photons"), std::string::npos) << over;
  EXPECT_NE(over.find("1024 MiB"), std::string::npos) << over;
  // A wrong type is an error too, granularity's included.
  EXPECT_NE(error_of(R"(<string name="granularity" value="many"/>)").find("mem/sppm.xml:4: "), std::string::npos);
}

// KNOWN BUG (disabled until fixed): maxPasses 0 loads (the range is [-1, 2^31 - 1]), then
// sppm_passes() gives a program of no passes and render() throws the internal "pass program:
// artifacts need a builder, and a builder artifacts". Like photonCount 0 it should be refused at
// load, naming the file, line and parameter.
TEST(SppmLoader, MaxPassesZeroIsRefused) {
  const std::string e = scene_error_of([] {
    load("<integrator type=\"sppm\">\n<integer name=\"maxDepth\" value=\"5\"/>\n<integer name=\"maxPasses\" value=\"0\"/>\n</integrator>");
  });
  EXPECT_NE(e.find("mem/sppm.xml:4: "), std::string::npos) << e;
  EXPECT_NE(e.find("max_passes"), std::string::npos) << e;
}

const char* kFog = R"(<shape type="sphere"><medium type="homogeneous" name="interior">
  <rgb name="sigmaT" value="0.5"/><rgb name="albedo" value="0.8"/></medium></shape>
)";

TEST(SppmLoader, AScenesMediaAreRenderedByVolpathWithANote) {
  LoadResult r = load("<integrator type=\"sppm\"><integer name=\"maxDepth\" value=\"9\"/></integrator>",
                      std::string(kPerspective) + kFog);
  EXPECT_EQ(r.scene->integrator.type, IntegratorType::VolPath);
  EXPECT_EQ(r.scene->integrator.max_depth, 9);
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "the 'sppm' integrator does not render participating media"), 1u);
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "rendered by 'volpath'"), 1u);
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Warning, "media"), 0u);
  // The same from the command line.
  LoadOptions opt;
  opt.integrator = "sppm";
  LoadResult cli = load("<integrator type=\"path\"/>", std::string(kPerspective) + kFog, "0.6.0", opt);
  EXPECT_EQ(cli.scene->integrator.type, IntegratorType::VolPath);
  EXPECT_EQ(count_messages(cli, LoadMessage::Level::Note, "the 'sppm' integrator does not render participating media"), 1u);
  // Without media it stays sppm, whatever the sensor (it only traces camera rays).
  EXPECT_EQ(load("<integrator type=\"sppm\"/>", "<sensor type=\"orthographic\">\n<film type=\"hdrfilm\"/></sensor>\n")
                .scene->integrator.type,
            IntegratorType::Sppm);
}

// A file without an integrator rendered with --integrator sppm gets sppm's defaults (rrDepth 3).
TEST(SppmLoader, CommandLineSppmWithoutAnIntegratorHasItsDefaults) {
  LoadOptions opt;
  opt.integrator = "sppm";
  LoadResult r = load("", kPerspective, "0.6.0", opt);
  EXPECT_EQ(r.scene->integrator.type, IntegratorType::Sppm);
  EXPECT_EQ(r.scene->integrator.rr_depth, 3);
}

TEST(SppmLoader, CommandLineSppmOverAPathTracerKeepsItsDepths) {
  LoadOptions opt;
  opt.integrator = "sppm";
  LoadResult r = load("<integrator type=\"path\">\n<integer name=\"maxDepth\" value=\"9\"/>\n<integer name=\"rrDepth\" value=\"2\"/>\n</integrator>",
                      kPerspective, "0.6.0", opt);
  const IntegratorSettings& s = r.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Sppm);
  EXPECT_EQ(s.max_depth, 9);
  EXPECT_EQ(s.rr_depth, 2);
  EXPECT_EQ(s.photon_count, 250000u);  // sppm's own parameters: its defaults
  EXPECT_FLOAT_EQ(s.alpha, 0.7f);
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Note,
                           "replaced by the 'sppm' integrator given on the command line; it keeps its maximum and "
                           "Russian roulette depths"),
            1u);
  // And the other way: an sppm scene rendered by path keeps sppm's depths.
  opt.integrator = "path";
  LoadResult back = load("<integrator type=\"sppm\">\n<integer name=\"maxDepth\" value=\"6\"/>\n<integer name=\"photonCount\" value=\"10\"/>\n</integrator>",
                         kPerspective, "0.6.0", opt);
  EXPECT_EQ(back.scene->integrator.type, IntegratorType::Path);
  EXPECT_EQ(back.scene->integrator.max_depth, 6);
  // "sppm" is one of the names --integrator takes.
  opt.integrator = "spm";
  const std::string unknown = scene_error_of([&] { load("<integrator type=\"path\"/>", kPerspective, "0.6.0", opt); });
  EXPECT_NE(unknown.find("sppm"), std::string::npos) << unknown;
}

}  // namespace
}  // namespace tessera
