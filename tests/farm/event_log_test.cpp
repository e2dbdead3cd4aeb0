// The coordinator's structured log (event_log.h): JSON lines that parse, text lines for people.
#include "event_log.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <sstream>

namespace tessera::server {
namespace {

// Routes spdlog's default logger into a string for the test's duration.
class CapturedLog {
 public:
  CapturedLog() : previous_(spdlog::default_logger()) {
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out_);
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", sink));
  }
  ~CapturedLog() {
    spdlog::set_default_logger(previous_);
    configure_logging("text", "info");
  }
  std::vector<std::string> lines() const {
    std::vector<std::string> v;
    std::istringstream in(out_.str());
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
  }

 private:
  std::ostringstream out_;
  std::shared_ptr<spdlog::logger> previous_;
};

TEST(EventLog, JsonLinesCarryTheEventAndItsFields) {
  CapturedLog log;
  configure_logging("json", "info");
  log_event(spdlog::level::info, "job.done", {{"job", 3}, {"seconds", 1.5}, {"name", "a \"quoted\"\nname"}});
  log_event(spdlog::level::debug, "lease.issued", {{"lease", 1}});  // below the level: not written
  spdlog::warn("plain message with \"quotes\"");
  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 2u);
  nlohmann::json a = parse_log_line(lines[0]);
  ASSERT_TRUE(a.is_object()) << lines[0];
  EXPECT_EQ(a["event"], "job.done");
  EXPECT_EQ(a["job"], 3);
  EXPECT_EQ(a["name"], "a \"quoted\"\nname");
  EXPECT_EQ(a["level"], "info");
  EXPECT_EQ(a["time"].get<std::string>().size(), 24u);  // 2026-12-01T22:51:26.021Z
  nlohmann::json b = parse_log_line(lines[1]);
  ASSERT_TRUE(b.is_object()) << lines[1];
  EXPECT_EQ(b["msg"], "plain message with \"quotes\"");
  EXPECT_EQ(b["level"], "warning");
}

TEST(EventLog, TextLinesAreKeyValue) {
  CapturedLog log;
  configure_logging("text", "debug");
  log_event(spdlog::level::debug, "lease.issued", {{"lease", 17}, {"worker", "w one"}});
  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("[debug] lease.issued lease=17 worker=\"w one\""), std::string::npos) << lines[0];
  EXPECT_THROW(configure_logging("xml", "info"), std::invalid_argument);
  EXPECT_THROW(configure_logging("json", "loud"), std::invalid_argument);
}

}  // namespace
}  // namespace tessera::server
