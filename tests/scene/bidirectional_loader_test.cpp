// The `bdpt` and `ptracer` integrators in scene files: their Mitsuba 0.6 and 3 parameters map onto
// IntegratorSettings, bad values name the file, line and parameter, scheduling-only parameters get
// a note and bruteForce is reported as unsupported, a scene with media is rendered by volpath with
// a note, and a sensor they cannot importance-sample is an error naming it.
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include "integrator_loading.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <string>

namespace tessera {
namespace {

using namespace tessera::test;

const IntegratorLoader load{"mem/bidir.xml"};

TEST(BidirectionalLoader, BdptMapsMitsuba06Parameters) {
  LoadResult r = load(R"(<integrator type="bdpt">
<integer name="maxDepth" value="7"/>
<integer name="rrDepth" value="3"/>
<boolean name="lightImage" value="false"/>
<boolean name="sampleDirect" value="false"/>
</integrator>)");
  const IntegratorSettings& s = r.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Bdpt);
  EXPECT_EQ(s.max_depth, 7);
  EXPECT_EQ(s.rr_depth, 3);
  EXPECT_FALSE(s.light_image);
  EXPECT_FALSE(s.sample_direct);
  EXPECT_TRUE(r.unsupported.empty());
  EXPECT_TRUE(r.messages.empty()) << r.messages[0].text;
}

TEST(BidirectionalLoader, BdptDefaultsAndEitherSpellingInA3File) {
  const IntegratorSettings d = load("<integrator type=\"bdpt\"/>").scene->integrator;
  EXPECT_EQ(d.type, IntegratorType::Bdpt);
  EXPECT_EQ(d.max_depth, -1);
  EXPECT_EQ(d.rr_depth, 5);
  EXPECT_TRUE(d.light_image);
  EXPECT_TRUE(d.sample_direct);
  // bdpt is not a Mitsuba 3 plugin: a 3.x file may keep 0.6's names or use the snake_case ones.
  for (const char* names : {"maxDepth,lightImage", "max_depth,light_image"}) {
    const std::string n = names, max = n.substr(0, n.find(',')), light = n.substr(n.find(',') + 1);
    LoadResult r = load("<integrator type=\"bdpt\"><integer name=\"" + max + "\" value=\"4\"/><boolean name=\"" + light +
                            "\" value=\"false\"/></integrator>",
                        kPerspective, "3.0.0");
    EXPECT_EQ(r.scene->integrator.max_depth, 4) << names;
    EXPECT_FALSE(r.scene->integrator.light_image) << names;
    EXPECT_TRUE(r.unsupported.empty()) << names;
  }
}

TEST(BidirectionalLoader, BadValuesNameFileLineAndParameter) {
  const std::string rr = scene_error_of([] {
    load("<integrator type=\"bdpt\">\n<integer name=\"rrDepth\" value=\"0\"/>\n</integrator>");
  });
  EXPECT_NE(rr.find("mem/bidir.xml:3: 'rr_depth' of integrator 'bdpt' must be in [1, "), std::string::npos) << rr;
  const std::string max = scene_error_of([] {
    load("<integrator type=\"bdpt\">\n<integer name=\"maxDepth\" value=\"-2\"/>\n</integrator>");
  });
  EXPECT_NE(max.find("mem/bidir.xml:3: 'max_depth' of integrator 'bdpt' must be in [-1, "), std::string::npos) << max;
  const std::string light = scene_error_of([] {
    load("<integrator type=\"bdpt\">\n<integer name=\"maxDepth\" value=\"3\"/>\n"
         "<boolean name=\"lightImage\" value=\"maybe\"/>\n</integrator>");
  });
  EXPECT_NE(light.find("mem/bidir.xml:4: "), std::string::npos) << light;
  EXPECT_NE(light.find("'maybe'"), std::string::npos) << light;
  const std::string ptracer = scene_error_of([] {
    load("<integrator type=\"ptracer\">\n<integer name=\"rrDepth\" value=\"0\"/>\n</integrator>");
  });
  EXPECT_NE(ptracer.find("mem/bidir.xml:3: 'rr_depth' of integrator 'ptracer'"), std::string::npos) << ptracer;
  // A parameter the 0.6 plugin does not have is reported like any other.
  const std::string hide = scene_error_of([] {
    load("<integrator type=\"bdpt\">\n<boolean name=\"hideEmitters\" value=\"true\"/>\n</integrator>");
  });
  EXPECT_NE(hide.find("mem/bidir.xml:3: parameter 'hideEmitters' of integrator 'bdpt'"), std::string::npos) << hide;
}

// vcm's rules for where merges happen: defaults (no direct light, only rough surfaces), values,
// and a roughness outside [0, 1] named with its file and line.
TEST(BidirectionalLoader, VcmReadsWhereItMerges) {
  const IntegratorSettings d = load("<integrator type=\"vcm\"/>").scene->integrator;
  EXPECT_EQ(d.type, IntegratorType::Vcm);
  EXPECT_FALSE(d.merge_direct);
  EXPECT_FLOAT_EQ(d.merge_roughness, 0.1f);
  LoadResult r = load(R"(<integrator type="vcm">
<boolean name="merge_direct" value="true"/>
<float name="merge_roughness" value="0"/>
</integrator>)");
  EXPECT_TRUE(r.scene->integrator.merge_direct);
  EXPECT_EQ(r.scene->integrator.merge_roughness, 0.f);
  EXPECT_TRUE(r.unsupported.empty());
  const std::string rough = scene_error_of([] {
    load("<integrator type=\"vcm\">\n<float name=\"merge_roughness\" value=\"1.5\"/>\n</integrator>");
  });
  EXPECT_NE(rough.find("mem/bidir.xml:3: 'merge_roughness' of integrator 'vcm' must be in [0, 1]"), std::string::npos)
      << rough;
}

TEST(BidirectionalLoader, PtracerNotesSchedulingAndReportsBruteForce) {
  LoadResult r = load(R"(<integrator type="ptracer">
<integer name="maxDepth" value="6"/>
<integer name="rrDepth" value="2"/>
<integer name="granularity" value="100000"/>
<boolean name="bruteForce" value="false"/>
</integrator>)");
  const IntegratorSettings& s = r.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Ptracer);
  EXPECT_EQ(s.max_depth, 6);
  EXPECT_EQ(s.rr_depth, 2);
  EXPECT_TRUE(r.unsupported.empty());  // bruteForce false is what Tessera does
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "parameter 'granularity' of integrator 'ptracer' only sets how "
                                                        "Mitsuba schedules"),
            1u);
  EXPECT_EQ(r.messages.size(), 1u);

  const std::string e = scene_error_of([] {
    load("<integrator type=\"ptracer\">\n<boolean name=\"bruteForce\" value=\"true\"/>\n</integrator>");
  });
  EXPECT_NE(e.find("mem/bidir.xml:3: parameter 'bruteForce' of integrator 'ptracer' (fallback: false"), std::string::npos)
      << e;
  LoadOptions allow;
  allow.allow_unsupported = true;
  LoadResult forced = load("<integrator type=\"ptracer\">\n<boolean name=\"bruteForce\" value=\"true\"/>\n</integrator>",
                           kPerspective, "0.6.0", allow);
  ASSERT_EQ(forced.unsupported.size(), 1u);
  EXPECT_EQ(forced.unsupported[0].loc.line, 3);
  EXPECT_EQ(forced.scene->integrator.type, IntegratorType::Ptracer);
}

TEST(BidirectionalLoader, PtracerTakesMitsuba3Parameters) {
  LoadResult r = load(R"(<integrator type="ptracer">
<integer name="max_depth" value="8"/>
<boolean name="hide_emitters" value="true"/>
<integer name="samples_per_pass" value="16"/>
</integrator>)",
                      kPerspective, "3.0.0");
  const IntegratorSettings& s = r.scene->integrator;
  EXPECT_EQ(s.type, IntegratorType::Ptracer);
  EXPECT_EQ(s.max_depth, 8);
  EXPECT_TRUE(s.hide_emitters);
  EXPECT_TRUE(r.unsupported.empty());
  EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "parameter 'samples_per_pass' of integrator 'ptracer'"), 1u);
}

const char* kFog = R"(<shape type="sphere"><medium type="homogeneous" name="interior">
  <rgb name="sigmaT" value="0.5"/><rgb name="albedo" value="0.8"/></medium></shape>
)";

TEST(BidirectionalLoader, AScenesMediaAreRenderedByVolpathWithANote) {
  for (const char* type : {"bdpt", "ptracer"}) {
    LoadResult r = load(std::string("<integrator type=\"") + type + "\"><integer name=\"maxDepth\" value=\"9\"/></integrator>",
                        std::string(kPerspective) + kFog);
    EXPECT_EQ(r.scene->integrator.type, IntegratorType::VolPath) << type;
    EXPECT_EQ(r.scene->integrator.max_depth, 9) << type;
    EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, std::string("the '") + type +
                                                              "' integrator does not render participating media"),
              1u)
        << type;
    EXPECT_EQ(count_messages(r, LoadMessage::Level::Note, "rendered by 'volpath'"), 1u) << type;
    EXPECT_EQ(count_messages(r, LoadMessage::Level::Warning, "media"), 0u) << type;
  }
  // The same from the command line.
  LoadOptions opt;
  opt.integrator = "bdpt";
  EXPECT_EQ(load("<integrator type=\"path\"/>", std::string(kPerspective) + kFog, "0.6.0", opt).scene->integrator.type,
            IntegratorType::VolPath);
}

TEST(BidirectionalLoader, ASensorItCannotSampleIsAnErrorNamingIt) {
  const std::string ortho = "<sensor type=\"orthographic\">\n<film type=\"hdrfilm\"/></sensor>\n";
  for (const char* type : {"bdpt", "ptracer"}) {
    const std::string e = scene_error_of([&] { load(std::string("<integrator type=\"") + type + "\"/>", ortho); });
    EXPECT_NE(e.find(std::string("mem/bidir.xml:3: the ") + type +
                     " integrator needs a sensor it can importance-sample (perspective or thinlens); this scene's is "
                     "sensor 'orthographic'"),
              std::string::npos)
        << e;
  }
  // A sensor Tessera substitutes a pinhole for, with --allow-unsupported, and the command line's override.
  LoadOptions allow;
  allow.allow_unsupported = true;
  const std::string spherical = scene_error_of([&] {
    load("<integrator type=\"bdpt\"/>", "<sensor type=\"spherical\">\n<film type=\"hdrfilm\"/></sensor>\n", "0.6.0", allow);
  });
  EXPECT_NE(spherical.find("mem/bidir.xml:3: the bdpt integrator needs"), std::string::npos) << spherical;
  EXPECT_NE(spherical.find("'spherical'"), std::string::npos) << spherical;
  LoadOptions opt;
  opt.integrator = "ptracer";
  EXPECT_NE(scene_error_of([&] { load("<integrator type=\"path\"/>", ortho, "0.6.0", opt); }).find("'orthographic'"),
            std::string::npos);
  // What it can sample: thin lens, and the camera fitted to a scene without a sensor; with media the
  // scene goes to volpath, which takes any sensor.
  EXPECT_EQ(load("<integrator type=\"bdpt\"/>",
                 "<sensor type=\"thinlens\"><float name=\"apertureRadius\" value=\"0.1\"/><film type=\"hdrfilm\"/></sensor>\n")
                .scene->integrator.type,
            IntegratorType::Bdpt);
  EXPECT_EQ(load("<integrator type=\"ptracer\"/>", "").scene->integrator.type, IntegratorType::Ptracer);
  EXPECT_EQ(load("<integrator type=\"bdpt\"/>", ortho + kFog).scene->integrator.type, IntegratorType::VolPath);
}

}  // namespace
}  // namespace tessera
