#include "event_log.h"

#include <spdlog/formatter.h>
#include <spdlog/pattern_formatter.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <ctime>

namespace tessera::server {

namespace {

std::atomic<bool> json_mode{false};

// Marks a payload that already is the inside of a JSON object ("event":..,"job":..).
constexpr char kRecordMark = '\x1e';

// Each line one object: time (UTC, milliseconds), level, then the event's fields or "msg".
class JsonFormatter final : public spdlog::formatter {
 public:
  void format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) override {
    using namespace std::chrono;
    const auto t = msg.time;
    const std::time_t secs = system_clock::to_time_t(t);
    const auto ms = duration_cast<milliseconds>(t.time_since_epoch()).count() % 1000;
    std::tm tm{};
    gmtime_r(&secs, &tm);
    char stamp[96];
    std::snprintf(stamp, sizeof stamp, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1,
                  tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, int(ms));
    const std::string_view payload(msg.payload.data(), msg.payload.size());
    const auto level = spdlog::level::to_string_view(msg.level);
    std::string line = "{\"time\":\"" + std::string(stamp) + "\",\"level\":\"" + std::string(level.data(), level.size()) + "\",";
    if (!payload.empty() && payload.front() == kRecordMark)
      line.append(payload.substr(1));
    else
      line += "\"msg\":" + nlohmann::json(std::string(payload)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    line += "}\n";
    dest.append(line.data(), line.data() + line.size());
  }
  std::unique_ptr<spdlog::formatter> clone() const override { return std::make_unique<JsonFormatter>(); }
};

std::string text_value(const nlohmann::json& v) {
  if (v.is_string()) {
    const std::string& s = v.get_ref<const std::string&>();
    const bool plain = !s.empty() && s.find_first_of(" \t\n\"'=") == std::string::npos;
    return plain ? s : v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  return v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

void configure_logging(const std::string& format, const std::string& level) {
  if (format != "text" && format != "json") throw std::invalid_argument("log format '" + format + "' is not text or json");
  const spdlog::level::level_enum lvl = spdlog::level::from_str(level);
  if (lvl == spdlog::level::off && level != "off") throw std::invalid_argument("log level '" + level + "' is unknown");
  json_mode = format == "json";
  if (json_mode)
    spdlog::set_formatter(std::make_unique<JsonFormatter>());
  else
    spdlog::set_pattern("%Y-%m-%d %H:%M:%S.%e [%l] %v");
  spdlog::set_level(lvl);
}

void log_event(spdlog::level::level_enum level, std::string_view event, const nlohmann::json& fields) {
  if (!spdlog::should_log(level)) return;
  std::string payload;
  if (json_mode) {
    nlohmann::json record = {{"event", event}};
    if (fields.is_object()) record.update(fields);
    std::string inside = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    payload = kRecordMark + inside.substr(1, inside.size() - 2);
  } else {
    payload = std::string(event);
    if (fields.is_object())
      for (auto it = fields.begin(); it != fields.end(); ++it) payload += " " + it.key() + "=" + text_value(it.value());
  }
  spdlog::log(level, "{}", payload);
}

nlohmann::json parse_log_line(const std::string& line) {
  nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
  return j.is_object() ? j : nlohmann::json();
}

}  // namespace tessera::server
