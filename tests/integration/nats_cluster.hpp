// A three-node NATS cluster with JetStream on loopback for the integration
// tests: real nats-server processes, each with its config file and store
// directory in the test's folder, on ports picked free. Stopped with the
// object (ChildProcess), also when a test fails half-way.
#pragma once

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <sstream>
#include <stdexcept>
#include <vector>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "child_process.hpp"

namespace sky::test {

// A port nothing listens on now (bound to 0 and closed again: the kernel
// does not hand it out again at once).
inline unsigned freeLoopbackPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  unsigned port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0)
    port = ntohs(a.sin_port);
  ::close(fd);
  return port;
}

inline bool acceptsConnections(unsigned port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

// A child process that the test may also pause and resume (SIGSTOP,
// SIGCONT) or kill; stopped like ChildProcess when the object goes away.
class PausableProcess {
 public:
  PausableProcess(std::vector<std::string> argv, const std::string& logPath) : logPath_(logPath) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot spawn " + argv[0]);
  }
  PausableProcess(const PausableProcess&) = delete;
  PausableProcess& operator=(const PausableProcess&) = delete;
  ~PausableProcess() {
    if (reaped_) return;
    ::kill(pid_, SIGCONT);
    ::kill(pid_, SIGTERM);
    if (!reap(std::chrono::seconds(20))) {
      ::kill(pid_, SIGKILL);
      reap(std::chrono::seconds(5));
    }
  }
  void pause() { ::kill(pid_, SIGSTOP); }
  void resume() { ::kill(pid_, SIGCONT); }
  void killNow() {
    if (reaped_) return;
    ::kill(pid_, SIGKILL);
    reap(std::chrono::seconds(5));
  }
  std::string log() const {
    std::ifstream f(logPath_);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }

 private:
  bool reap(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) return reaped_ = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  pid_t pid_ = -1;
  std::string logPath_;
  bool reaped_ = false;
};

// The nats-server executable CMake found (deploy/setup installs Debian's), or
// a skip: a failure when SKY_REQUIRE_DEPS is set, as for every dependency.
#define SKY_REQUIRE_NATS_SERVER()                                                              \
  do {                                                                                         \
    if (std::string(SKY_NATS_SERVER).empty() || !std::filesystem::exists(SKY_NATS_SERVER)) {   \
      if (std::getenv("SKY_REQUIRE_DEPS"))                                                     \
        FAIL() << "nats-server not installed (deploy/setup installs it) and SKY_REQUIRE_DEPS is set"; \
      GTEST_SKIP() << "nats-server not installed (deploy/setup installs it)";                  \
    }                                                                                          \
  } while (0)

class NatsCluster {
 public:
  static constexpr int kNodes = 3;

  // maxPayload_bytes: the nodes' max_payload (0: NATS's default, 1 MiB).
  explicit NatsCluster(const std::filesystem::path& dir, std::size_t maxPayload_bytes = 0)
      : dir_(dir), maxPayload_bytes_(maxPayload_bytes) {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    // Six distinct ports: a port freed by one call can come back from the
    // next (two nodes given one route port: one failed to listen).
    std::vector<unsigned> taken;
    const auto distinctPort = [&] {
      unsigned port = freeLoopbackPort();
      while (std::find(taken.begin(), taken.end(), port) != taken.end()) port = freeLoopbackPort();
      taken.push_back(port);
      return port;
    };
    for (int i = 0; i < kNodes; ++i) {
      clientPorts_[i] = distinctPort();
      routePorts_[i] = distinctPort();
    }
    for (int i = 0; i < kNodes; ++i) writeConfig(i);
    for (int i = 0; i < kNodes; ++i) start(i);
  }

  // Every node accepts clients (JetStream may still be electing its meta
  // leader: the servers' clients retry until it answers).
  bool waitReady(std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (int i = 0; i < kNodes; ++i)
      while (!acceptsConnections(clientPorts_[i])) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    return true;
  }

  std::string url(int i) const { return "nats://127.0.0.1:" + std::to_string(clientPorts_[i]); }
  // Every node's URL, comma-separated, the order rotated to start at `first`.
  std::string urls(int first = 0) const {
    std::string s;
    for (int k = 0; k < kNodes; ++k) s += (k ? "," : "") + url((first + k) % kNodes);
    return s;
  }
  // Every node's URL, one an element (NatsLogOptions::urls).
  std::vector<std::string> urlList() const {
    std::vector<std::string> v;
    for (int k = 0; k < kNodes; ++k) v.push_back(url(k));
    return v;
  }
  bool accepts(int i) const { return acceptsConnections(clientPorts_[i]); }
  void kill(int i) { nodes_[i]->killNow(); }
  void start(int i) {
    nodes_[i].emplace(std::vector<std::string>{SKY_NATS_SERVER, "-c", (dir_ / ("n" + std::to_string(i) + ".conf")).string()},
                      (dir_ / ("n" + std::to_string(i) + ".log")).string());
  }

 private:
  void writeConfig(int i) const {
    std::ofstream f(dir_ / ("n" + std::to_string(i) + ".conf"));
    f << "server_name: n" << i << "\n"
      << "listen: 127.0.0.1:" << clientPorts_[i] << "\n";
    if (maxPayload_bytes_ > 0) f << "max_payload: " << maxPayload_bytes_ << "\n";
    f
      << "jetstream { store_dir: \"" << (dir_ / ("store" + std::to_string(i))).string()
      << "\", max_memory_store: 64MB, max_file_store: 256MB }\n"
      << "cluster {\n  name: skytest\n  listen: 127.0.0.1:" << routePorts_[i] << "\n  routes: [\n";
    for (int k = 0; k < kNodes; ++k)
      if (k != i) f << "    nats-route://127.0.0.1:" << routePorts_[k] << "\n";
    f << "  ]\n}\n";
  }

  std::filesystem::path dir_;
  std::size_t maxPayload_bytes_ = 0;
  std::array<unsigned, kNodes> clientPorts_{}, routePorts_{};
  std::array<std::optional<ChildProcess>, kNodes> nodes_;
};

}  // namespace sky::test
