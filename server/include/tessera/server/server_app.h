// `tessera-server`: options, the HTTP server, local workers and signal handling. main.cpp only
// calls server_main().
#pragma once

#include "tessera/server/coordinator.h"

#include <string>

namespace tessera::server {

struct ServerOptions {
  std::string listen = "127.0.0.1:8420";  // HOST:PORT; port 0 picks a free one
  std::string port_file;                  // write the bound port here (for scripts and tests)
  int http_threads = 32;                  // cpp-httplib thread pool
  int local_workers = 0;
  int local_worker_threads = 0;           // 0: the machine's cores divided among the local workers
  std::string worker_binary;              // default: tessera-worker beside this program
  std::string client_token, client_token_file, worker_token, worker_token_file;  // auth.h
  std::string tls_cert, tls_key;          // PEM files; both set: serve https only
  double header_timeout = 10;             // seconds a connection may take to send a request's headers
  double min_upload_rate = 65536;         // bytes/s a body must average after its grace (else 408)
  double upload_grace = 10;               // seconds a body may take to start, and its longest pause
  int max_uploads = 16;                   // bundles (scenes, jobs) received at once, all clients
  int max_uploads_per_client = 4;         // ... from one client address
  int max_result_uploads = 32;            // workers' results received at once, all workers
  int max_result_uploads_per_host = 16;   // ... from one address
  std::string log_format = "text";        // text or json (one JSON object per line)
  std::string log_level = "info";         // debug shows every lease; info every job state change
  std::string record_responses;           // file: every answer, a JSON line each (response_recorder.h)
  CoordinatorOptions coordinator;
};

/// Parses argv (CLI11) into options; returns an exit code >= 0 when the program should stop
/// (--help, bad flags), -1 to go on.
int parse_server_args(int argc, char** argv, ServerOptions& options);
/// Runs until SIGTERM/SIGINT; returns the exit code.
int run_server(const ServerOptions& options);
/// `tessera-server --plan-scene`: plans one scene for the coordinator (scene_planner.h), reading
/// the request on stdin and answering on stdout; the exit code.
int run_scene_planner_main();

}  // namespace tessera::server
