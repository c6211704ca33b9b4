// A child process for integration tests: spawned with its output in a log
// file, and always stopped (SIGTERM, then SIGKILL) when the object goes away,
// also when the test fails half-way.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <string_view>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace sky::test {

class ChildProcess {
 public:
  // env: extra NAME=value entries on top of this process's environment.
  ChildProcess(std::vector<std::string> argv, const std::string& logPath, std::vector<std::string> env = {})
      : logPath_(logPath) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    // An entry of `env` replaces the inherited variable of the same name
    // (getenv would return the first of two).
    std::vector<char*> envp;
    for (char** e = environ; *e; ++e) {
      const std::string_view inherited(*e);
      const bool overridden = std::any_of(env.begin(), env.end(), [&](const std::string& o) {
        const auto eq = o.find('=');
        return inherited.substr(0, inherited.find('=')) == std::string_view(o).substr(0, eq);
      });
      if (!overridden) envp.push_back(*e);
    }
    for (auto& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);
    const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot spawn " + argv[0]);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() { stop(); }

  // The process id (for /proc: sky_weatherd_relay_bench reads its CPU time).
  pid_t pid() const { return pid_; }

  // Waits for the process to exit by itself; nullopt on timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    if (exitCode_) return exitCode_;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return exitCode_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

  // SIGTERM, then SIGKILL if it is still there after a grace period: 20 s,
  // since a renderer ends its frame first, and under ASan beside the suite's
  // other tests a first frame (the shaders' JIT compile and both weather
  // maps) has taken 5 s.
  int stop() {
    if (exitCode_) return *exitCode_;
    kill(pid_, SIGTERM);
    if (auto c = wait(std::chrono::seconds(20))) return *c;
    kill(pid_, SIGKILL);
    return wait(std::chrono::seconds(5)).value_or(-1);
  }

  // SIGKILL now (a crash: no shutdown code runs), then reap it.
  int killNow() {
    if (exitCode_) return *exitCode_;
    kill(pid_, SIGKILL);
    return wait(std::chrono::seconds(5)).value_or(-1);
  }

  std::string log() const {
    std::ifstream f(logPath_);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }

 private:
  pid_t pid_ = -1;
  std::string logPath_;
  std::optional<int> exitCode_;
};

// Waits until a port file appears (written atomically by the process) and
// returns the port, or 0 on timeout.
inline unsigned waitForPortFile(const std::string& path, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    std::ifstream f(path);
    unsigned port = 0;
    if (f >> port && port > 0) return port;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

}  // namespace sky::test
