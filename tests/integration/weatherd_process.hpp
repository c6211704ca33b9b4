// skyshell-weatherd as a child process for the integration tests: started on
// ephemeral ports (stream, HTTP API, optionally CIGI) with a per-test token,
// and HTTP requests to its API.
#pragma once

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "child_process.hpp"
#include "sky/sim/http_client.hpp"

namespace sky::test {

using namespace std::chrono_literals;

inline constexpr const char* kToken = "s3cret-test-token";

struct Weatherd {
  std::filesystem::path dir;
  std::optional<ChildProcess> process;
  unsigned streamPort = 0, httpPort = 0, cigiPort = 0;

  // extra: more command-line arguments (e.g. --db FILE).
  explicit Weatherd(const std::string& name, const std::string& scenario = SKY_SCENARIO_CLOUDY, bool cigi = false,
                    const std::vector<std::string>& extra = {}) {
    dir = std::filesystem::path(SKY_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "token") << kToken << "\n";
    std::vector<std::string> args{SKY_WEATHERD, "--scenario", scenario, "--port", "0", "--port-file",
                                  (dir / "weatherd.port").string(), "--http-port", "0",
                                  "--http-port-file", (dir / "http.port").string(), "--token-file",
                                  (dir / "token").string(), "--heartbeat-ms", "200"};
    if (cigi) args.insert(args.end(), {"--cigi-port", "0", "--cigi-port-file", (dir / "cigi.port").string()});
    args.insert(args.end(), extra.begin(), extra.end());
    process.emplace(args, (dir / "weatherd.log").string());
    streamPort = waitForPortFile((dir / "weatherd.port").string(), 20s);
    httpPort = waitForPortFile((dir / "http.port").string(), 20s);
    if (cigi) cigiPort = waitForPortFile((dir / "cigi.port").string(), 20s);
  }

  sim::HttpResponse request(const std::string& method, const std::string& target, const std::string& body = "",
                            const std::string& token = kToken) {
    sim::HttpRequest r;
    r.method = method;
    r.port = static_cast<unsigned short>(httpPort);
    r.target = target;
    r.body = body;
    r.bearerToken = token;
    auto response = sim::httpRequest(r);
    EXPECT_TRUE(response) << describe(response.error());
    return response ? *response : sim::HttpResponse{};
  }
};

}  // namespace sky::test
