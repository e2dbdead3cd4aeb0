// How `tessera`'s subcommands join its command line: each command file adds its own subcommand,
// options and all (CLI11), and says what runs once they are parsed; main_entry() only lists them.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace tessera::cli {

struct ConnectionOptions;

/// A subcommand added to the app: run() is called if it was the one parsed; its exit code.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command add_render_command(CLI::App& app);
Command add_denoise_command(CLI::App& app);
Command add_compare_command(CLI::App& app);
/// `bench` and its subcommands (rays, convergence): one Command per runnable subcommand.
std::vector<Command> add_bench_commands(CLI::App& app);
Command add_convergence_command(CLI::App& bench);
Command add_submit_command(CLI::App& app);
Command add_jobs_command(CLI::App& app);
Command add_cancel_command(CLI::App& app);

/// --server, --token-file and --ca-file: how every farm command reaches its coordinator.
void add_connection_options(CLI::App& command, ConnectionOptions& connection);
/// --integrator (render, submit, bench convergence): the scene's integrator replaced by one of
/// Tessera's (the farm runs every one).
void add_integrator_option(CLI::App& command, std::string& integrator);
/// "-D name=value" options into `out`; false, with the message printed as `who`'s, on a bad one.
bool parse_defines(const std::vector<std::string>& given, std::map<std::string, std::string>& out, const char* who);

}  // namespace tessera::cli
