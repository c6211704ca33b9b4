// A storm of changes posted to skyshell-weatherd by several clients at once,
// and what a restarted server shows of it: the tests of its durability
// (kill -9 in weatherd_crash_test.cpp, SIGTERM in weatherd_lifecycle_test.cpp)
// drive the same storm and read the survivors the same way.
//
// Client c's batch sets layer 10+c (and 20+c with two layers per batch) to
// base_m = 1000 + marker; each client's markers only grow, so its layers hold
// at least its last acknowledged marker after any restart.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "sky/sim/http_client.hpp"

namespace sky::test {

inline Result<sim::HttpResponse> callWeatherd(unsigned port, const std::string& token, const std::string& method,
                                              const std::string& target, const std::string& body = "") {
  sim::HttpRequest r;
  r.method = method;
  r.port = static_cast<unsigned short>(port);
  r.target = target;
  r.body = body;
  r.bearerToken = token;
  r.timeout = std::chrono::milliseconds(3000);
  return sim::httpRequest(r);
}

// One POST /api/changes body: client's layers (1 or 2 of them) to the marker.
inline std::string stormBatch(int client, int marker, int layers) {
  auto layer = [&](int id) {
    return nlohmann::json{{"id", id},
                          {"type", "stratocumulus"},
                          {"base_m", 1000 + marker},
                          {"thickness_m", 500},
                          {"transition_band_m", 0},
                          {"coverage", 0.5},
                          {"density", 1},
                          {"wind", {{"speed_mps", 5}, {"from_deg", 270}, {"vertical_mps", 0}}}};
  };
  nlohmann::json changes = nlohmann::json::array();
  changes.push_back({{"op", "set_layer"}, {"layer", layer(10 + client)}});
  if (layers == 2) changes.push_back({{"op", "set_layer"}, {"layer", layer(20 + client)}});
  return nlohmann::json{{"author", "client" + std::to_string(client)}, {"changes", changes}}.dump();
}

struct Acked {
  int client = 0;
  int marker = 0;
  std::uint64_t sequence = 0;
};

// What the storm saw, over every cycle of a test.
struct StormRecord {
  std::vector<Acked> acked;
  std::map<int, int> lastAttempt;  // client -> highest marker sent (answered or not)
  std::map<int, int> lastAcked;    // client -> highest marker acknowledged
  std::size_t unanswered = 0;
};

// `clients` threads posting batches to `port` as fast as they are answered,
// until stop(). An answer other than 200 (when there is one) fails the test:
// a server being killed may leave a request unanswered, never refused.
class ChangeStorm {
 public:
  ChangeStorm(unsigned port, std::string token, int clients, int layers, StormRecord& record)
      : record_(record) {
    for (int c = 0; c < clients; ++c)
      threads_.emplace_back([this, port, token, layers, c] {
        while (!stopped_) {
          int marker = 0;
          {
            std::lock_guard lock(mutex_);
            marker = ++record_.lastAttempt[c];
          }
          auto reply = callWeatherd(port, token, "POST", "/api/changes", stormBatch(c, marker, layers));
          std::lock_guard lock(mutex_);
          if (reply && reply->status == 200) {
            record_.acked.push_back({c, marker, nlohmann::json::parse(reply->body)["sequence"].get<std::uint64_t>()});
            record_.lastAcked[c] = marker;
          } else {
            ++record_.unanswered;
            if (reply) ADD_FAILURE() << "client " << c << ": HTTP " << reply->status << " " << reply->body;
          }
        }
      });
  }
  ChangeStorm(const ChangeStorm&) = delete;
  ChangeStorm& operator=(const ChangeStorm&) = delete;
  ~ChangeStorm() { stop(); }

  // Lets the clients finish the request they are in, and joins them.
  void stop() {
    stopped_ = true;
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }

 private:
  StormRecord& record_;
  std::mutex mutex_;
  std::atomic<bool> stopped_{false};
  std::vector<std::thread> threads_;
};

// What a (re)started server shows: its sequence, each layer's base and the
// event log's authors by sequence (the newest `eventLimit`).
struct Survivors {
  std::uint64_t sequence = 0;
  std::map<int, double> base;
  std::map<std::uint64_t, std::string> authors;
};

inline Result<Survivors> readSurvivors(unsigned port, const std::string& token, std::size_t eventLimit = 10000) {
  auto state = callWeatherd(port, token, "GET", "/api/state");
  if (!state) return tl::unexpected(state.error());
  auto events = callWeatherd(port, token, "GET", "/api/events?limit=" + std::to_string(eventLimit));
  if (!events) return tl::unexpected(events.error());
  if (state->status != 200 || events->status != 200)
    return fail(ErrorCode::Io, "GET /api/state or /api/events: HTTP " + std::to_string(state->status) + ", " +
                                   std::to_string(events->status));
  Survivors s;
  const auto stateJson = nlohmann::json::parse(state->body);
  s.sequence = stateJson["sequence"].get<std::uint64_t>();
  for (const auto& l : stateJson["layers"]) s.base[l["id"].get<int>()] = l["base_m"].get<double>();
  const auto eventsJson = nlohmann::json::parse(events->body);
  for (const auto& e : eventsJson["events"]) s.authors[e["sequence"].get<std::uint64_t>()] = e["author"].get<std::string>();
  return s;
}

}  // namespace sky::test
