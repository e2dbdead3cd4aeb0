#include "scene_planner.h"

#include "tessera/scene/error.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string_view>

extern char** environ;

namespace tessera::server {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Loader messages name files by their path in the data directory; users know them by their path
// in the bundle.
std::string strip_dir(std::string msg, const std::string& dir) {
  for (const std::string& prefix : {fs::weakly_canonical(dir).string() + "/", dir + "/"})
    for (size_t at; (at = msg.find(prefix)) != std::string::npos;) msg.erase(at, prefix.size());
  for (const std::string& root : {fs::weakly_canonical(dir).string(), dir})  // the folder itself
    for (size_t at; (at = msg.find(root)) != std::string::npos;) msg.replace(at, root.size(), "<bundle>");
  return msg;
}

Status load_failed(const std::string& error, const std::string& detail) {
  return make_error(Code::Unprocessable, error, detail);
}

json request_json(const PlanRequest& r) {
  return {{"bundle_dir", r.bundle_dir}, {"scene_file", r.scene_file}, {"settings", to_json(r.settings)}};
}

bool request_from_json(const json& j, PlanRequest& out, std::string& error) {
  if (!j.is_object() || !j.contains("bundle_dir") || !j.contains("scene_file") || !j.contains("settings") ||
      !j["bundle_dir"].is_string() || !j["scene_file"].is_string()) {
    error = "scene planner: malformed request";
    return false;
  }
  out.bundle_dir = j["bundle_dir"].get<std::string>();
  out.scene_file = j["scene_file"].get<std::string>();
  return job_settings_from_json(j["settings"], out.settings, error, /*require_scene=*/false);
}

Result<JobPlan> answer_from_json(const std::string& text, const std::string& bundle_dir) {
  json j = json::parse(text, nullptr, false);
  JobPlan plan;
  std::string error;
  if (j.is_object() && j.contains("plan") && job_plan_from_json(j["plan"], plan, error)) return plan;
  if (j.is_object() && j.value("error", "") != "" && j.contains("detail") && j["detail"].is_string())
    return load_failed(j["error"].get<std::string>(), strip_dir(j["detail"].get<std::string>(), bundle_dir));
  return make_error(Code::Internal, "internal", "the scene planner answered nonsense: " + text.substr(0, 200));
}

// Writes all of `bytes` to `fd` (EINTR-safe); false on error.
bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(size_t(n));
  }
  return true;
}

std::string read_all(int fd) {
  std::string out;
  char buf[1 << 14];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof(buf));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return out;
    out.append(buf, size_t(n));
  }
}

// posix_spawn with the child's stdin/stdout on pipes and every signal unblocked (the server blocks
// SIGTERM/SIGINT in its threads). Returns the pid, or -1.
pid_t spawn_planner(const std::string& program, int to_child[2], int from_child[2]) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, to_child[0], 0);
  posix_spawn_file_actions_adddup2(&actions, from_child[1], 1);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  std::string arg0 = program, arg1 = "--plan-scene";
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = -1;
  if (posix_spawn(&pid, program.c_str(), &actions, &attr, argv, environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  return pid;
}

}  // namespace

Result<JobPlan> plan_scene_here(const PlanRequest& r) {
  try {
    LoadedJobScene loaded = load_job_scene(r.bundle_dir, r.scene_file, r.settings);
    return make_job_plan(r.bundle_dir, r.scene_file, r.settings, loaded);
  } catch (const UnsupportedError& e) {
    return load_failed("scene_unsupported", strip_dir(e.what(), r.bundle_dir));
  } catch (const std::exception& e) {  // SceneError and whatever a loader throws
    return load_failed("scene_load_failed", strip_dir(e.what(), r.bundle_dir));
  }
}

Result<JobPlan> plan_scene_in_child(const std::string& program, const PlanRequest& request) {
  int to_child[2], from_child[2];
  if (::pipe2(to_child, O_CLOEXEC) != 0) return make_error(Code::Internal, "internal", "pipe: " + std::string(std::strerror(errno)));
  if (::pipe2(from_child, O_CLOEXEC) != 0) {
    ::close(to_child[0]);
    ::close(to_child[1]);
    return make_error(Code::Internal, "internal", "pipe: " + std::string(std::strerror(errno)));
  }
  const pid_t pid = spawn_planner(program, to_child, from_child);
  ::close(to_child[0]);
  ::close(from_child[1]);
  std::string answer;
  if (pid > 0) {
    (void)write_all(to_child[1], request_json(request).dump());  // (small: fits the pipe's buffer)
    ::close(to_child[1]);
    answer = read_all(from_child[0]);
  } else {
    ::close(to_child[1]);
  }
  ::close(from_child[0]);
  if (pid <= 0) return make_error(Code::Internal, "internal", "cannot run the scene planner " + program);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status))
    return load_failed("scene_load_failed", "loading the scene crashed the scene check (signal " +
                                                std::to_string(WTERMSIG(status)) + ")");
  return answer_from_json(answer, request.bundle_dir);
}

int run_scene_planner(std::FILE* in, std::FILE* out) {
  std::string text;
  char buf[1 << 14];
  for (size_t n; (n = std::fread(buf, 1, sizeof(buf), in)) > 0;) text.append(buf, n);
  PlanRequest request;
  std::string error;
  json answer;
  if (!request_from_json(json::parse(text, nullptr, false), request, error)) {
    answer = {{"error", "internal"}, {"detail", error}};
  } else {
    Result<JobPlan> plan = plan_scene_here(request);
    answer = plan.ok() ? json{{"plan", to_json(plan.value)}} : json{{"error", plan.status.error}, {"detail", plan.status.detail}};
  }
  const std::string bytes = answer.dump();
  return std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size() && std::fflush(out) == 0 ? 0 : 1;
}

}  // namespace tessera::server
