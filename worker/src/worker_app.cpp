#include "tessera/worker/worker_app.h"

#include "tessera/farm/build_fingerprint.h"
#include "tessera/worker/worker.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <signal.h>

#include <cstdio>
#include <optional>
#include <thread>

namespace tessera::farm {

int worker_main(int argc, char** argv) {
  CLI::App app{"tessera-worker: renders tiles for a Tessera coordinator"};
  WorkerOptions o;
  double budget_mb = 0;
  app.add_option("--server", o.server, "coordinator URL, http://HOST:PORT or https://HOST:PORT")->required();
  app.add_option("--ca-file", o.ca_file, "PEM file to verify an https coordinator's certificate (default: system CAs)")
      ->check(CLI::ExistingFile);
  app.add_option("--threads", o.threads, "render threads (default: every core)")->check(CLI::Range(0, 4096));
  app.add_option("--cache-dir", o.cache_dir, "where scene bundles are kept, one worker per folder (default: ~/.cache/tessera-worker)");
  app.add_option("--name", o.name, "name shown by the coordinator (default: host name)");
  app.add_option("--memory-budget", budget_mb, "MB of loaded scenes kept in memory (default: half the RAM)");
  app.add_option("--poll-wait", o.poll_wait, "seconds per lease long poll")->check(CLI::Range(0.0, 30.0))->capture_default_str();
  app.add_option("--max-leases", o.max_leases, "exit after this many leases (benchmarks)");
  std::string token_file;
  app.add_option("--token-file", token_file, "read the worker token from this file (else $TESSERA_WORKER_TOKEN)");
  // What registration sends about this build, for scripts and docs/api.md's curl examples: a
  // coordinator accepts only workers whose fingerprint matches its own.
  app.add_flag_callback(
      "--fingerprint",
      [] {
        const BuildFingerprint& fp = build_fingerprint();
        std::printf("%s\n", nlohmann::json{{"version", fp.version}, {"isa", fp.isa}, {"probe", fp.probe}}.dump().c_str());
        throw CLI::Success();
      },
      "print this build's fingerprint (version, isa, probe) as JSON and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    o.token = resolve_token("", token_file, "TESSERA_WORKER_TOKEN");
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  o.memory_budget = uint64_t(budget_mb * 1048576.0);

  // SIGTERM/SIGINT: finish what is being rendered, hand back the rest, sign off. A second signal
  // exits at once.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  ::signal(SIGPIPE, SIG_IGN);

  std::optional<Worker> made;
  try {
    made.emplace(o);
  } catch (const std::exception& e) {  // (its cache folder in use, or not writable)
    spdlog::error("{}", e.what());
    return 2;
  }
  Worker& worker = *made;
  std::atomic<bool> done{false};
  std::thread signal_thread([&] {
    int count = 0;
    while (!done) {
      timespec tick{0, 200 * 1000 * 1000};
      int sig = sigtimedwait(&signals, nullptr, &tick);
      if (sig == SIGTERM || sig == SIGINT) {
        if (++count > 1) std::_Exit(130);
        spdlog::info("signal {}: finishing current passes, then signing off", sig);
        worker.request_stop();
      }
    }
  });
  int code = worker.run();
  done = true;
  signal_thread.join();
  return code;
}

}  // namespace tessera::farm
