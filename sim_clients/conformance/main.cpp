// skyshell-conformance: the conformance check along a replayed flight. Reads
// the frames.jsonl of a headless replay (skyshell-render --replay --out DIR),
// asks the weather server's GET /api/conformance at a point every --every
// seconds of flight, each at the weather clock its frame drew, and writes the
// table along the flight: DIR/conformance.json and DIR/conformance.md.
//
// Exit codes: 0 every station in reach drew its report (or none was in
// reach), 1 the server could not be reached or answered an error, 2 bad
// input (command line, frames file), 3 a station's check failed.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>

#include "sky/sim/conformance_track.hpp"
#include "sky/sim/http_client.hpp"

namespace fs = std::filesystem;

namespace {

constexpr int kExitRuntime = 1, kExitBadInput = 2, kExitCheckFailed = 3;

// The replay's folder: frames.jsonl lies in its frames/ subfolder.
fs::path replayFolderOf(const fs::path& frames) {
  const fs::path folder = frames.parent_path();
  return folder.filename() == "frames" ? folder.parent_path() : folder;
}

}  // namespace

int main(int argc, char** argv) {
  std::string api, framesPath, outDir;
  sky::sim::TrackSampling sampling;
  sky::sim::TrackCheckOptions check;
  double radius_km = check.radius_m / 1000;
  CLI::App app{"skyshell-conformance: the weather server's conformance check along a replayed flight"};
  app.add_option("--api", api, "the weather server's HTTP API, http://HOST:PORT")->required();
  app.add_option("--frames", framesPath, "a headless replay's frames.jsonl (DIR/frames/frames.jsonl)")->required();
  app.add_option("--out", outDir, "where conformance.json and conformance.md go (default: the replay's folder)");
  app.add_option("--every", sampling.every_s, "flight seconds between checked points")->check(CLI::Range(0.001, 86400.0));
  app.add_option("--max-points", sampling.maxPoints, "at most this many points")->check(CLI::Range(1, 100000));
  app.add_option("--radius-km", radius_km, "stations and grid points within this of each point")
      ->check(CLI::Range(0.001, 20000.0));
  app.add_option("--stations", check.stations, "at most this many stations per point")->check(CLI::Range(0, 10000));
  app.add_option("--grid-points", check.gridPoints, "at most this many forecast grid points per point")
      ->check(CLI::Range(0, 2000));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitBadInput;
  }
  check.radius_m = radius_km * 1000;
  const auto endpoint = sky::sim::parseHttpEndpoint(api);
  if (!endpoint) {
    std::fprintf(stderr, "skyshell-conformance: --api: %s\n", sky::describe(endpoint.error()).c_str());
    return kExitBadInput;
  }
  std::ifstream in(framesPath, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "skyshell-conformance: %s: cannot open\n", framesPath.c_str());
    return kExitBadInput;
  }
  const auto track = sky::sim::sampleTrack(in, framesPath, sampling);
  if (!track) {
    std::fprintf(stderr, "skyshell-conformance: %s\n", sky::describe(track.error()).c_str());
    return kExitBadInput;
  }
  const fs::path out = outDir.empty() ? replayFolderOf(framesPath) : fs::path(outDir);

  std::vector<sky::sim::PointCheck> checks;
  std::size_t failed = 0;
  for (std::size_t i = 0; i < track->size(); ++i) {
    const sky::sim::TrackPoint& p = (*track)[i];
    sky::sim::HttpRequest request;
    request.host = endpoint->first;
    request.port = endpoint->second;
    request.target = sky::sim::conformanceTarget(p, check);
    const auto answer = sky::sim::httpRequest(request);
    if (!answer) {
      std::fprintf(stderr, "skyshell-conformance: GET %s: %s\n", request.target.c_str(),
                   sky::describe(answer.error()).c_str());
      return kExitRuntime;
    }
    if (answer->status != 200) {
      std::fprintf(stderr, "skyshell-conformance: GET %s: HTTP %d\n", request.target.c_str(), answer->status);
      return kExitRuntime;
    }
    auto c = sky::sim::readPointCheck(p, answer->body, check.stations);
    if (!c) {
      std::fprintf(stderr, "skyshell-conformance: GET %s: %s\n", request.target.c_str(),
                   sky::describe(c.error()).c_str());
      return kExitRuntime;
    }
    std::size_t ok = 0;
    for (const auto& s : c->stations) ok += s.ok;
    failed += c->stations.size() - ok;
    std::fprintf(stderr, "skyshell-conformance: point %zu of %zu (flight %.0f s): %zu of %zu stations ok, %zu of %zu grid points\n",
                 i + 1, track->size(), p.flight_s, ok, c->stations.size(), c->gridOk, c->gridPoints);
    checks.push_back(std::move(*c));
  }

  std::error_code ec;
  fs::create_directories(out, ec);
  std::ofstream json(out / "conformance.json", std::ios::trunc);
  json << sky::sim::trackJson(checks, check).dump(2) << '\n';
  std::ofstream md(out / "conformance.md", std::ios::trunc);
  md << sky::sim::trackMarkdown(checks, check);
  if (!json || !md) {
    std::fprintf(stderr, "skyshell-conformance: %s: cannot write conformance.json and conformance.md\n",
                 out.string().c_str());
    return kExitRuntime;
  }
  std::printf("skyshell-conformance: %zu points checked, %zu station checks failed; wrote %s/conformance.{json,md}\n",
              checks.size(), failed, out.string().c_str());
  return failed > 0 ? kExitCheckFailed : 0;
}
