// skyshell-scenario: flies a scenario's flight as a CIGI host (like
// skyshell-replay) and, in step with the flight's time, sends its weather
// actions to the weather server's API (POST /api/changes). Example:
// deploy/sim-scenarios/climb-into-sun.toml.

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <boost/asio.hpp>

#include "sky/flight/utf8_text.hpp"
#include "sky/sim/flight_file.hpp"
#include "sky/sim/http_client.hpp"
#include "sky/sim/replay_session.hpp"
#include "sky/sim/sim_scenario.hpp"

namespace asio = boost::asio;

namespace {

// Exit codes: 0 flown and every action accepted, 1 runtime failure, 2 bad
// input (command line, scenario, flight), 3 the server refused an action or
// could not be reached.
constexpr int kExitRuntime = 1, kExitBadInput = 2, kExitActionFailed = 3;
// A server's answer is echoed up to this many bytes (ill-formed UTF-8 and
// control characters replaced): enough for any error the API gives, and a
// misbehaving server cannot flood the log.
constexpr std::size_t kMaxEchoedBody = 2000;

// Sends actions in order on their own thread, so a slow server never delays
// the host's frames.
class ActionSender {
 public:
  ActionSender(std::string host, unsigned short port, std::string token)
      : host_(std::move(host)), port_(port), token_(std::move(token)), thread_([this] { run(); }) {}
  ~ActionSender() { finish(); }

  void send(const sky::sim::ScenarioAction& a, double flightTime_s) {
    std::lock_guard lock(mutex_);
    queue_.push_back({a, flightTime_s});
    wake_.notify_one();
  }
  // Sends what is queued, then stops the thread.
  void finish() {
    {
      std::lock_guard lock(mutex_);
      if (done_) return;
      done_ = true;
      wake_.notify_one();
    }
    thread_.join();
  }
  int failures() const { return failures_; }
  int accepted() const { return accepted_; }

 private:
  struct Item {
    sky::sim::ScenarioAction action;
    double flightTime_s;
  };
  void run() {
    for (;;) {
      Item item;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return done_ || !queue_.empty(); });
        if (queue_.empty()) return;
        item = std::move(queue_.front());
        queue_.pop_front();
      }
      nlohmann::json body = item.action.request;
      if (body.is_object() && !body.contains("author")) body["author"] = "skyshell-scenario";
      sky::sim::HttpRequest r;
      r.method = "POST";
      r.host = host_;
      r.port = port_;
      r.target = item.action.target;
      r.body = body.dump();
      r.bearerToken = token_;
      auto response = sky::sim::httpRequest(r);
      if (!response) {
        ++failures_;
        std::printf("scenario: t=%.1f s: %s: NOT SENT: %s\n", item.flightTime_s, item.action.what.c_str(),
                    sky::describe(response.error()).c_str());
      } else if (response->status != 200) {
        ++failures_;
        std::printf("scenario: t=%.1f s: %s: REFUSED (HTTP %d, scenario line %zu): %s\n", item.flightTime_s,
                    item.action.what.c_str(), response->status, item.action.line,
                    sky::flight::messageText(response->body, kMaxEchoedBody).c_str());
      } else {
        ++accepted_;
        std::printf("scenario: t=%.1f s: %s: accepted %s\n", item.flightTime_s, item.action.what.c_str(),
                    sky::flight::messageText(response->body, kMaxEchoedBody).c_str());
      }
      std::fflush(stdout);
    }
  }

  std::string host_;
  unsigned short port_;
  std::string token_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Item> queue_;
  bool done_ = false;
  int failures_ = 0, accepted_ = 0;
  std::thread thread_;
};

}  // namespace

int main(int argc, char** argv) {
  std::string scenarioPath, api = "http://127.0.0.1:47880", token, tokenFile;
  double speed = 0;
  bool dryRun = false;
  sky::sim::ReplayOptions o;
  o.name = "scenario";
  CLI::App app{"skyshell-scenario: fly a scenario's flight as a CIGI host and send its timed weather actions"};
  app.add_option("scenario", scenarioPath, "scenario TOML (see sim_clients/include/sky/sim/sim_scenario.hpp)")
      ->required();
  app.add_option("--host", o.host, "IG (renderer) address");
  app.add_option("--port", o.port, "IG (renderer) CIGI UDP port")->check(CLI::Range(1, 65535));
  app.add_option("--api", api, "weather server HTTP API, http://HOST:PORT");
  app.add_option("--token", token, "weather server token for changes");
  app.add_option("--token-file", tokenFile, "read the token from this file (first line)");
  app.add_option("--speed", speed, "override the scenario's replay speed")->check(CLI::Range(0.05, 100.0));
  app.add_option("--rate", o.rate_hz, "host frames per second")->check(CLI::Range(1.0, 1000.0));
  app.add_option("--conditions-rate", o.conditionsRate_hz, "Environmental Conditions Requests per flight second (0: none)")
      ->check(CLI::Range(0.0, 60.0));
  app.add_option("--conditions-csv", o.conditionsCsv, "log the IG's condition answers here");
  app.add_flag("--quiet", o.quiet, "no progress lines (actions are still printed)");
  app.add_flag("--dry-run", dryRun, "check the scenario and its flight, print the actions, send nothing");
  bool noHost = false;
  app.add_flag("--no-host", noHost,
               "send only the weather actions, on the flight's clock, without flying it as a CIGI host (when "
               "a renderer replays the flight headless itself)");
  CLI11_PARSE(app, argc, argv);

  auto scenario = sky::sim::loadSimScenario(scenarioPath);
  if (!scenario) {
    std::fprintf(stderr, "skyshell-scenario: %s\n", sky::describe(scenario.error()).c_str());
    return kExitBadInput;
  }
  auto flight = sky::sim::loadFlight(scenario->flightFile.string());
  if (!flight) {
    std::fprintf(stderr, "skyshell-scenario: %s: flight: %s\n", sky::flight::messageText(scenarioPath).c_str(),
                 sky::describe(flight.error()).c_str());
    return kExitBadInput;
  }
  for (const auto& w : flight->warnings) std::fprintf(stderr, "skyshell-scenario: warning: %s\n", w.c_str());
  if (dryRun) {
    std::printf("scenario: %s: flight %s (%.0f s), %zu actions\n", scenarioPath.c_str(),
                scenario->flightFile.string().c_str(), flight->duration_s(), scenario->actions.size());
    for (const auto& a : scenario->actions)
      std::printf("scenario: t=%.1f s: %s: POST %s %s\n", a.at_s, a.what.c_str(), a.target.c_str(),
                  a.request.dump().c_str());
    return 0;
  }
  if (!tokenFile.empty()) {
    std::ifstream in(tokenFile);
    if (!in || !std::getline(in, token)) {
      std::fprintf(stderr, "skyshell-scenario: cannot read --token-file %s\n", tokenFile.c_str());
      return kExitBadInput;
    }
  }
  auto endpoint = sky::sim::parseHttpEndpoint(api);
  if (!endpoint) {
    std::fprintf(stderr, "skyshell-scenario: --api %s\n", sky::describe(endpoint.error()).c_str());
    return kExitBadInput;
  }
  o.speed = speed > 0 ? speed : scenario->speed;
  o.start_s = scenario->start_s;
  o.end_s = scenario->end_s;

  try {
    ActionSender sender(endpoint->first, endpoint->second, token);
    asio::io_context io;
    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](boost::system::error_code ec, int) {
      if (!ec) io.stop();
    });
    std::size_t next = 0;
    const auto& actions = scenario->actions;
    if (noHost) {
      // The flight's clock alone: flight time = start + wall time x speed.
      const double first = flight->fixes.front().time_s;
      const double t0 = first + o.start_s;
      const double t1 = o.end_s >= 0 ? std::min(first + o.end_s, flight->fixes.back().time_s) : flight->fixes.back().time_s;
      const auto wall0 = std::chrono::steady_clock::now();
      asio::steady_timer timer(io);
      std::function<void()> tick = [&] {
        const double t =
            t0 + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count() * o.speed;
        while (next < actions.size() && actions[next].at_s <= t - first) sender.send(actions[next], t - first), ++next;
        if (t >= t1 || next == actions.size()) {
          signals.cancel();
          return;
        }
        timer.expires_after(std::chrono::milliseconds(20));
        timer.async_wait([&](boost::system::error_code ec) {
          if (!ec) tick();
        });
      };
      tick();
      io.run();
      sender.finish();
      std::printf("scenario: done: %d of %zu actions accepted, %d refused or not sent\n", sender.accepted(),
                  actions.size(), sender.failures());
      return sender.failures() > 0 || next < actions.size() ? kExitActionFailed : 0;
    }
    sky::sim::ReplaySession session(io, o, std::move(*flight), [&] { signals.cancel(); });
    session.onTick([&](double t) {
      while (next < actions.size() && actions[next].at_s <= t) sender.send(actions[next++], t);
    });
    session.start();
    io.run();
    sender.finish();
    std::printf("scenario: done: %d of %zu actions accepted, %d refused or not sent\n", sender.accepted(),
                actions.size(), sender.failures());
    if (session.exitCode() != 0) return kExitRuntime;
    return sender.failures() > 0 || next < actions.size() ? kExitActionFailed : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "skyshell-scenario: %s\n", e.what());
    return kExitRuntime;
  }
}
