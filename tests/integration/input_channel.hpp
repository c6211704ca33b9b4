// A weather server and a headless renderer that takes its camera from UDP
// (CIGI, and FlightGear FDM or ForeFlight lines; ports ephemeral), as the
// input tests need them:
// 64x36 frames, since they are about the camera path and the inputs, and a
// small frame keeps the frame rate up under ASan on lavapipe.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "child_process.hpp"

namespace sky::test {

struct InputChannel {
  std::filesystem::path dir;
  std::optional<ChildProcess> weatherd, render;
  // inputPort: the FlightGear FDM or ForeFlight port. 0: did not come up (see the logs).
  unsigned weatherPort = 0, cigiPort = 0, inputPort = 0;

  enum class Input { FlightGear, ForeFlight };

  // name: the folder under SKY_TEST_OUTPUT_DIR; idleExit_s: the renderer
  // exits that long after its inputs fell silent; extra: more renderer
  // arguments.
  InputChannel(const std::string& name, const std::string& idleExit_s, const std::vector<std::string>& extra = {},
               Input input = Input::FlightGear) {
    using namespace std::chrono_literals;
    dir = std::filesystem::path(SKY_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string d = dir.string();
    weatherd.emplace(std::vector<std::string>{SKY_WEATHERD, "--scenario", SKY_SCENARIO_CLOUDY, "--port", "0",
                                              "--port-file", d + "/weatherd.port", "--heartbeat-ms", "200"},
                     d + "/weatherd.log");
    weatherPort = waitForPortFile(d + "/weatherd.port", 20s);
    if (weatherPort == 0) return;
    const bool fdm = input == Input::FlightGear;
    const std::string portFile = d + (fdm ? "/fdm.port" : "/foreflight.port");
    std::vector<std::string> args{SKY_RENDER,
                                  "--headless",
                                  "--server",
                                  "127.0.0.1:" + std::to_string(weatherPort),
                                  "--cigi-port",
                                  "0",
                                  "--port-file",
                                  d + "/cigi.port",
                                  fdm ? "--fdm-port" : "--foreflight-port",
                                  "0",
                                  fdm ? "--fdm-port-file" : "--foreflight-port-file",
                                  portFile,
                                  "--out",
                                  d + "/frames",
                                  "--width",
                                  "64",
                                  "--height",
                                  "36",
                                  "--idle-exit",
                                  idleExit_s,
                                  "--weather-timeout",
                                  "60"};
    args.insert(args.end(), extra.begin(), extra.end());
    // Leak checking off for the renderer only, as in skeleton_test.cpp:
    // lavapipe's JIT leaves allocations no suppression can name.
    render.emplace(args, d + "/render.log", std::vector<std::string>{"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
    inputPort = waitForPortFile(portFile, 90s);
    if (inputPort != 0) cigiPort = waitForPortFile(d + "/cigi.port", 5s);
  }
};

}  // namespace sky::test
