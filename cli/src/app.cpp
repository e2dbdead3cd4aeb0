// The command line of `tessera` (CLI11): each subcommand adds itself (command_line.h); this only
// lists them, parses, and runs the one chosen.
#include "tessera/cli/command_line.h"
#include "tessera/cli/commands.h"

#include <csignal>
#include <iostream>

namespace tessera::cli {

bool parse_defines(const std::vector<std::string>& given, std::map<std::string, std::string>& out, const char* who) {
  for (const std::string& kv : given) {
    const size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::cerr << who << ": -D expects name=value, got '" << kv << "'\n";
      return false;
    }
    out[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  return true;
}

void add_connection_options(CLI::App& command, ConnectionOptions& c) {
  command.add_option("--server", c.server, "Coordinator URL (default: $TESSERA_SERVER or http://127.0.0.1:8420)");
  command.add_option("--token-file", c.token_file, "Client token file (default: $TESSERA_CLIENT_TOKEN)");
  command.add_option("--ca-file", c.ca_file, "PEM file to verify an https server (default: system CAs)")
      ->check(CLI::ExistingFile);
}

void add_integrator_option(CLI::App& command, std::string& integrator) {
  // The loader's integrator names (LoadOptions::integrator); it checks them too.
  command.add_option("--integrator", integrator, "Override the integrator: path, volpath, direct, bdpt, ptracer, sppm or vcm")
      ->check(CLI::IsMember({"path", "volpath", "direct", "bdpt", "ptracer", "sppm", "vcm"}));
}

int main_entry(int argc, char** argv) {
  // A coordinator refusing an upload closes the connection without reading the rest: the write
  // then fails with EPIPE and the answer (a 413 naming the limit) is printed, not a silent death.
  ::signal(SIGPIPE, SIG_IGN);
  CLI::App app{"Tessera: a physically based path tracer for Mitsuba scenes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("tessera ") + TESSERA_VERSION);
  std::vector<Command> commands = {add_render_command(app)};
  for (Command& c : add_bench_commands(app)) commands.push_back(std::move(c));
  for (auto add : {add_denoise_command, add_compare_command, add_submit_command, add_jobs_command, add_cancel_command})
    commands.push_back(add(app));
  CLI11_PARSE(app, argc, argv);
  for (const Command& c : commands)
    if (c.app->parsed()) return c.run();
  return 2;
}

}  // namespace tessera::cli
