// `tessera jobs` and `tessera cancel`: a coordinator's jobs listed, and one cancelled.
#include "farm_connection.h"

#include "tessera/cli/command_line.h"

#include <cstdio>
#include <iostream>
#include <memory>

namespace tessera::cli {

using nlohmann::json;

int run_jobs(const JobsOptions& o) {
  client::FarmApi api(client::FarmClient(""));
  if (!connect(o.connection, "tessera jobs", api)) return 2;
  client::HttpReply r = api.jobs();
  json j = r.json();
  if (!r.ok() || !j.is_object()) {
    std::cerr << "tessera jobs: " << farm_error(r, o.connection) << "\n";
    return 1;
  }
  std::printf("%6s  %-10s %6s %9s %11s %6s  %s\n", "ID", "STATE", "PRIO", "PROGRESS", "SIZE", "SPP", "NAME");
  for (const json& job : j["jobs"])
    std::printf("%6llu  %-10s %6d %8.1f%% %5dx%-5d %6d  %s\n", (unsigned long long)job.value("id", uint64_t(0)),
                job.value("state", "").c_str(), job.value("priority", 0), 100.0 * job.value("progress", 0.0),
                job.value("width", 0), job.value("height", 0),
                job.value("stopped_at_target", false) ? job.value("spp_done", 0) : job.value("spp", 0), job.value("name", "").c_str());
  return 0;
}

int run_cancel(const JobsOptions& o) {
  client::FarmApi api(client::FarmClient(""));
  if (!connect(o.connection, "tessera cancel", api)) return 2;
  client::HttpReply r = api.cancel_job(o.cancel_id);
  if (!r.ok()) {
    std::cerr << "tessera cancel: " << farm_error(r, o.connection) << "\n";
    return 1;
  }
  std::cerr << "job " << o.cancel_id << " cancelled\n";
  return 0;
}

Command add_jobs_command(CLI::App& app) {
  auto o = std::make_shared<JobsOptions>();
  CLI::App* jobs = app.add_subcommand("jobs", "List a coordinator's jobs");
  add_connection_options(*jobs, o->connection);
  return {jobs, [o] { return run_jobs(*o); }};
}

Command add_cancel_command(CLI::App& app) {
  auto o = std::make_shared<JobsOptions>();
  CLI::App* cancel = app.add_subcommand("cancel", "Cancel a job");
  cancel->add_option("id", o->cancel_id, "Job id")->required();
  add_connection_options(*cancel, o->connection);
  return {cancel, [o] { return run_cancel(*o); }};
}

}  // namespace tessera::cli
