// The coordinator's log: spdlog, as text for people or as JSON lines for log shippers
// (--log-format json). State changes are events with a stable name and ids as fields, one line
// each: "job.submitted", "job.started", "job.done", "job.failed", "job.cancelled", "job.retried",
// "job.priority", "lease.issued", "lease.done", "lease.expired", "lease.failed",
// "worker.registered", "worker.refused", "worker.lost", "worker.draining", "worker.signed_off",
// "connection.cut_off". Leases log at debug level (thousands per second), the rest at info or above.
//
// Text:  2026-12-01 22:05:01.123 [info] job.done job=3 seconds=12.5
// JSON:  {"time":"2026-12-01T22:05:01.123Z","level":"info","event":"job.done","job":3,"seconds":12.5}
// A plain spdlog message in JSON mode becomes {"time":..,"level":..,"msg":"..."}.
#pragma once

#include <nlohmann/json.hpp>
#include <spdlog/common.h>

#include <string>
#include <string_view>

namespace tessera::server {

/// Installs the format ("text" or "json") and level ("debug", "info", "warn", "error") on
/// spdlog's default logger (stderr). Throws std::invalid_argument on an unknown name.
void configure_logging(const std::string& format, const std::string& level);

/// One event; `fields` must be a JSON object (ids, counts, reasons).
void log_event(spdlog::level::level_enum level, std::string_view event, const nlohmann::json& fields);

/// Parses one JSON log line (tests, tools): the object, or null if `line` is not one.
nlohmann::json parse_log_line(const std::string& line);

}  // namespace tessera::server
