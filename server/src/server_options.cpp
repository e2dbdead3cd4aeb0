// tessera-server's command line. Every limit a hostile or careless client could hit is a flag, so
// an operator can tighten it without a rebuild (docs/api.md lists them with their errors).
#include "tessera/server/server_app.h"

#include <CLI/CLI.hpp>

namespace tessera::server {

namespace {

void add_service_options(CLI::App& app, ServerOptions& o) {
  CoordinatorOptions& c = o.coordinator;
  app.add_option("--listen", o.listen, "HOST:PORT to listen on (port 0: any free port)")->capture_default_str();
  app.add_option("--port-file", o.port_file, "write the port actually bound to this file");
  app.add_option("--data-dir", c.data_dir, "directory for the state database, bundles and scenes")->capture_default_str();
  app.add_option("--http-threads", o.http_threads,
                 "HTTP worker threads (long polls use at most half of them); uploads have threads of their own")
      ->check(CLI::Range(2, 4096))->capture_default_str();
  app.add_option("--local-workers", o.local_workers, "also run N workers on this machine")->check(CLI::Range(0, 256));
  app.add_option("--local-worker-threads", o.local_worker_threads, "threads per local worker (default: cores / N)");
  app.add_option("--worker-binary", o.worker_binary, "the tessera-worker program for --local-workers");
  app.add_option("--heartbeat-interval", c.heartbeat_interval,
                 "seconds between worker heartbeats; a worker silent for 3 intervals is dead and its leases re-issued")
      ->check(CLI::Range(0.1, 600.0))->capture_default_str();
  app.add_flag("!--no-speculation", c.speculate,
               "never lease a second copy of an outstanding unit to an idle worker (each unit is leased once)");
  app.add_option("--speculate-after", c.speculate_after,
                 "an idle worker may get a copy of a unit whose lease has run this many times the job's median "
                 "unit time (0: at once)")
      ->check(CLI::Range(0.0, 1000.0))->capture_default_str();
  app.add_option("--max-poll-wait", c.max_poll_wait, "longest lease long poll, seconds")
      ->check(CLI::Range(0.0, 30.0))->capture_default_str();
  app.add_option("--commit-interval", c.commit_interval,
                 "seconds: under load, the state database commits (one fsync) at most this often, every lease "
                 "and result decided meanwhile together; 0 commits as soon as the previous commit ends")
      ->check(CLI::Range(0.0, 0.1))->capture_default_str();
  app.add_option("--denoise-threads", c.denoise_threads,
                 "threads that denoise a finished job's image (jobs with denoise), one job at a time; 0: every core. "
                 "The image does not depend on it")
      ->check(CLI::Range(0, 256))->capture_default_str();
}

void add_security_options(CLI::App& app, ServerOptions& o) {
  auto* security = "Security";
  app.add_option("--client-token", o.client_token, "bearer token for clients (else $TESSERA_CLIENT_TOKEN)")->group(security);
  app.add_option("--client-token-file", o.client_token_file, "read the client token from this file")->group(security);
  app.add_option("--worker-token", o.worker_token, "bearer token for workers (else $TESSERA_WORKER_TOKEN)")->group(security);
  app.add_option("--worker-token-file", o.worker_token_file, "read the worker token from this file")->group(security);
  auto* cert = app.add_option("--tls-cert", o.tls_cert, "PEM certificate (chain): serve https")
                   ->check(CLI::ExistingFile)->group(security);
  auto* key = app.add_option("--tls-key", o.tls_key, "PEM private key of --tls-cert")->check(CLI::ExistingFile)->group(security);
  cert->needs(key);
  key->needs(cert);
  app.add_option("--header-timeout", o.header_timeout,
                 "seconds a connection may take to send a request's headers (slow clients are cut off)")
      ->check(CLI::Range(0.5, 600.0))->capture_default_str()->group(security);
  app.add_option("--webhook-allow", o.coordinator.webhook_allow,
                 "URL prefix a job's webhook must start with (repeatable; default: any)")
      ->group(security);
}

void add_limit_options(CLI::App& app, CoordinatorOptions& c) {
  auto* limits = "Limits";
  app.add_option("--max-upload", c.max_upload_bytes, "largest scene bundle accepted, bytes")->capture_default_str()->group(limits);
  app.add_option("--max-unpacked", c.bundle_limits.max_unpacked_bytes, "largest unpacked bundle, bytes")
      ->capture_default_str()->group(limits);
  app.add_option("--max-ratio", c.bundle_limits.max_ratio,
                 "a bundle may unpack to at most 8 MiB + this many times its own size (decompression bombs); 0: no ratio limit")
      ->check(CLI::NonNegativeNumber)->capture_default_str()->group(limits);
  app.add_option("--max-files", c.bundle_limits.max_files, "most entries in a bundle")->capture_default_str()->group(limits);
  app.add_option("--max-spp", c.limits.max_spp, "most samples per pixel of a job")
      ->check(CLI::PositiveNumber)->capture_default_str()->group(limits);
  app.add_option("--max-resolution", c.limits.max_resolution, "largest image side, pixels")
      ->check(CLI::PositiveNumber)->capture_default_str()->group(limits);
  app.add_option("--max-pixels", c.limits.max_pixels, "most pixels of an image")->check(CLI::PositiveNumber)
      ->capture_default_str()->group(limits);
  app.add_option("--max-tiles", c.limits.max_tiles, "most tiles of a job")->check(CLI::PositiveNumber)
      ->capture_default_str()->group(limits);
  app.add_option("--max-active-jobs", c.max_active_jobs, "most queued and running jobs; more are refused (429)")
      ->check(CLI::PositiveNumber)->capture_default_str()->group(limits);
}

// Uploads hold an HTTP thread while their body arrives: a minimum rate bounds how long, and slots
// how many (upload_slots.h); the pool has a thread for each slot beyond --http-threads.
void add_upload_options(CLI::App& app, ServerOptions& o) {
  auto* limits = "Limits";
  app.add_option("--min-upload-rate", o.min_upload_rate,
                 "bytes/s a request body must average once its first --upload-grace seconds are over (else 408): a "
                 "body of N bytes has at most grace + N / rate seconds")
      ->check(CLI::Range(1.0, 1e12))->capture_default_str()->group(limits);
  app.add_option("--upload-grace", o.upload_grace,
                 "seconds a request body may take to start arriving, and the longest it may pause (else 408)")
      ->check(CLI::Range(0.5, 600.0))->capture_default_str()->group(limits);
  app.add_option("--max-uploads", o.max_uploads, "scene and job uploads received at once, all clients together (else 503)")
      ->check(CLI::Range(1, 4096))->capture_default_str()->group(limits);
  app.add_option("--max-uploads-per-client", o.max_uploads_per_client,
                 "scene and job uploads received at once from one client address (else 503)")
      ->check(CLI::Range(1, 4096))->capture_default_str()->group(limits);
  app.add_option("--max-result-uploads", o.max_result_uploads,
                 "workers' result uploads received at once, in slots of their own (else 503; workers retry)")
      ->check(CLI::Range(1, 4096))->capture_default_str()->group(limits);
  app.add_option("--max-result-uploads-per-host", o.max_result_uploads_per_host,
                 "workers' result uploads received at once from one address (else 503; workers retry)")
      ->check(CLI::Range(1, 4096))->capture_default_str()->group(limits);
}

void add_retention_options(CLI::App& app, CoordinatorOptions& c) {
  auto* retention = "Retention";
  app.add_option("--retain-days", c.retain_days,
                 "delete finished jobs (results, image) this many days after they ended, and bundles unused as long; 0: keep")
      ->check(CLI::NonNegativeNumber)->capture_default_str()->group(retention);
  app.add_option("--retain-bytes", c.retain_bytes,
                 "above this many bytes of results, images and bundles, delete the oldest finished jobs first; 0: no limit")
      ->capture_default_str()->group(retention);
}

void add_logging_options(CLI::App& app, ServerOptions& o) {
  auto* logging = "Logging";
  app.add_option("--log-format", o.log_format, "text, or json: one JSON object per line")
      ->check(CLI::IsMember({"text", "json"}))->capture_default_str()->group(logging);
  app.add_option("--record-responses", o.record_responses,
                 "append every answer (method, path, status, JSON body) to this file, a JSON object a line: for "
                 "checking the API description (docs/openapi.json) against real traffic")
      ->group(logging);
  app.add_option("--log-level", o.log_level, "debug (every lease), info (every job), warn or error")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}))->capture_default_str()->group(logging);
}

}  // namespace

int parse_server_args(int argc, char** argv, ServerOptions& o) {
  CLI::App app{"tessera-server: the Tessera render farm coordinator"};
  add_service_options(app, o);
  add_security_options(app, o);
  add_limit_options(app, o.coordinator);
  add_upload_options(app, o);
  add_retention_options(app, o.coordinator);
  add_logging_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  // Long polls may hold at most half the HTTP threads; the rest always serve clients.
  o.coordinator.max_waiting_polls = std::max(1, o.http_threads / 2);
  return -1;
}

}  // namespace tessera::server
