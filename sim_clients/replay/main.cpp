// skyshell-replay: replays a recorded flight as a CIGI 3.3 host over UDP, in
// real time (optionally scaled), so a renderer channel flies it as it would
// fly a simulator's ownship.
#include <cstdio>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <boost/asio.hpp>

#include "sky/flight/clean.hpp"
#include "sky/flight/info.hpp"
#include "sky/sim/flight_file.hpp"
#include "sky/sim/replay_session.hpp"

namespace asio = boost::asio;

namespace {

struct Options : sky::sim::ReplayOptions {
  std::string flightPath;
  sky::flight::ReadOptions read;
  bool noClean = false;
  bool info = false;
  sky::flight::CleanOptions clean;
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"skyshell-replay: replay a recorded flight as a CIGI 3.3 host over UDP"};
  app.add_option("flight", o.flightPath,
                 "flight file: .csv (time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg, or ADS-B columns "
                 "such as OpenSky's), .igc or .gpx")
      ->required();
  app.add_option("--host", o.host, "IG (renderer) address");
  app.add_option("--port", o.port, "IG (renderer) CIGI UDP port")->check(CLI::Range(1, 65535));
  app.add_option("--ig", o.igs,
                 "an IG (renderer channel) to send every host datagram to, ADDR:PORT or [ADDR]:PORT; repeat for "
                 "each channel of a display (replaces --host/--port; conditions requests go to the first)");
  app.add_option("--channels", o.channels,
                 "channels of the display, side by side: with --channel-width-deg every frame carries View "
                 "Definition and View Control for view ids 0..N-1, left to right")
      ->check(CLI::Range(1, 64));
  app.add_option("--channel-width-deg", o.channelWidth_deg,
                 "horizontal field of view of each channel, deg; channel i looks (i - (N-1)/2) x W right of the nose")
      ->check(CLI::Range(0.0, 176.0));  // half-angles within the renderer's +-89 deg
  app.add_option("--channel-aspect", o.aspect,
                 "width / height of each channel (the vertical half-angles: atan(tan(W/2) / aspect))")
      ->check(CLI::Range(0.05, 20.0));
  app.add_option("--rate", o.rate_hz, "host frames per second")->check(CLI::Range(1.0, 1000.0));
  app.add_option("--speed", o.speed, "replay speed factor")->check(CLI::Range(0.05, 100.0));
  app.add_option("--start", o.start_s, "start offset into the flight, s")->check(CLI::NonNegativeNumber);
  app.add_option("--end", o.end_s, "end offset into the flight, s (default: the whole flight)");
  app.add_flag("--loop", o.loop, "start again at the end");
  app.add_flag("--little-endian", o.littleEndian, "send little-endian CIGI (default big-endian)");
  app.add_flag("--quiet", o.quiet, "no progress lines");
  app.add_flag("--sync", o.sync,
               "synchronous: send each host frame once every IG answered the one before with Start of Frame "
               "(renderers run with --cigi-sync); the flight advances 1/--rate x --speed per frame");
  app.add_option("--conditions-rate", o.conditionsRate_hz,
                 "Environmental Conditions Requests (weather + aerosol) at the ownship per second of flight; "
                 "0: none")
      ->check(CLI::Range(0.0, 60.0));
  app.add_option("--conditions-csv", o.conditionsCsv,
                 "write every answer (wind, temperature, cloud per layer) to this CSV file");
  app.add_option("--icao24", o.read.icao24,
                 "ADS-B .csv holding several aircraft: replay this one (ICAO 24-bit address, hex)");
  app.add_option("--track", o.read.track,
                 "KML/KMZ holding several tracks: replay this one, by its name (the error without it lists them)");
  std::string altitudeUnit;
  app.add_option("--altitude-unit", altitudeUnit,
                 "ADS-B .csv: unit of the altitude columns, ft or m (default: as each column's name says)")
      ->check(CLI::IsMember({"ft", "m"}));
  app.add_flag("--no-clean", o.noClean,
               "replay the track as read: no sorting, no dropping of repeats, speed glitches or spoofed jumps, "
               "gaps interpolated whatever their length");
  std::string maxSpeed;
  app.add_option("--max-speed", maxSpeed,
                 "cleaning: the fastest ground speed the aircraft flies, m/s or with a unit ('680kt', '350m/s'); "
                 "a fix implying more is dropped (default 350 m/s: an airliner with a jet-stream tailwind)");
  app.add_option("--max-gap", o.clean.maxGap_s,
                 "cleaning: longest gap between fixes flown through in a straight line, s; longer gaps are held "
                 "or end the replay (--long-gap)")
      ->check(CLI::Range(1.0, 1e7));
  std::string longGap = "hold";
  app.add_option("--long-gap", longGap,
                 "at a gap longer than --max-gap: hold (stay at the last fix, then jump to the next) or end")
      ->check(CLI::IsMember({"hold", "end"}));
  app.add_flag("--info", o.info,
               "print what the file holds (format, aircraft, time span, fixes kept and dropped, bounding box, "
               "altitude source) and exit without replaying");
  CLI11_PARSE(app, argc, argv);
  if (!altitudeUnit.empty())
    o.read.altitudeUnit = altitudeUnit == "ft" ? sky::flight::AltitudeUnit::Feet : sky::flight::AltitudeUnit::Metres;
  if (!maxSpeed.empty()) {
    const auto v = sky::flight::parseSpeed_mps(maxSpeed);
    if (!v) {
      std::fprintf(stderr, "skyshell-replay: --max-speed '%s' is not a speed (e.g. 350, 350m/s, 680kt)\n",
                   maxSpeed.c_str());
      return 2;
    }
    o.clean.maxGroundSpeed_mps = *v;
  }
  o.clean.longGap = longGap == "end" ? sky::flight::LongGap::End : sky::flight::LongGap::Hold;

  auto text = sky::sim::readFlightFile(o.flightPath);
  auto flight = text ? sky::flight::parseFlight(*text, o.flightPath, o.read)
                     : sky::Result<sky::flight::ParsedFlight>(tl::unexpected(text.error()));
  if (!flight) {
    std::fprintf(stderr, "skyshell-replay: %s\n", sky::describe(flight.error()).c_str());
    return 2;
  }
  std::optional<sky::flight::CleanReport> cleaning;
  if (!o.noClean) {
    auto cleaned = sky::flight::clean(*flight, o.clean, o.flightPath);
    if (!cleaned) {
      std::fprintf(stderr, "skyshell-replay: %s\n", sky::describe(cleaned.error()).c_str());
      return 2;
    }
    cleaning = std::move(*cleaned);
  }
  if (o.info) {
    const auto lines = sky::flight::describeFlight(*flight, sky::flight::formatName(*text, o.flightPath),
                                                   cleaning ? &*cleaning : nullptr, o.clean);
    for (const auto& line : lines) std::printf("%s\n", line.c_str());
    return 0;
  }
  for (const auto& warning : flight->warnings) std::fprintf(stderr, "skyshell-replay: warning: %s\n", warning.c_str());
  if (!flight->altitudeSource.empty())
    std::fprintf(stderr, "skyshell-replay: altitude: %s\n", flight->altitudeSource.c_str());
  if (cleaning)
    for (const auto& line : cleaning->lines(o.clean))
      std::fprintf(stderr, "skyshell-replay: cleaning: %s\n", line.c_str());
  else
    std::fprintf(stderr, "skyshell-replay: cleaning off (--no-clean): the track as read\n");
  try {
    asio::io_context io;
    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](boost::system::error_code ec, int) {
      if (!ec) io.stop();
    });
    sky::sim::ReplaySession replay(io, o, std::move(*flight), [&] { signals.cancel(); });
    replay.start();
    io.run();
    return replay.exitCode();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "skyshell-replay: %s\n", e.what());
    return 1;
  }
}
