// libFuzzer target: bytes a subscriber sends, through a real server session.
// One skyshell server (sky_server's Server, as skyshell-weatherd runs it) on
// a loopback port serves for the whole run; each input is written as it is
// (length prefixes and payloads: whole frames, or garbage) on a fresh TCP
// connection, whose sending side is then closed. The bytes take the path they
// take from any socket: the session's read, the subscriber's frame cap, the
// decoder, the handlers, snapshots and deltas out. The server must never
// crash, must send Hello first, and must close the connection after the
// input's EOF within the deadline (a hang is a bug).
// Seeds: tests/fuzz/corpus/stream_session/ (frames from encodeFrame).
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#include "sky/server/scenario.hpp"
#include "sky/server/server.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

// How long one input may take before the server is taken to hang.
constexpr int kDeadline_s = 5;

struct Rig {
  std::unique_ptr<sky::server::Server> server;
  std::thread thread;
  asio::io_context clientIo;

  Rig() {
    sky::server::Scenario scenario;
    scenario.clock = {1000.0, 1.0};
    sky::weather::CloudLayer l;
    l.id = 1;
    l.base_m = 1500;
    l.thickness_m = 1000;
    l.coverage = 0.5;
    l.density = 1;
    scenario.layers = {l};
    sky::server::ServerOptions options;
    options.port = 0;
    options.handleSignals = false;
    options.heartbeatInterval = std::chrono::milliseconds(1000);
    auto made = sky::server::Server::create(options, sky::server::WeatherState(scenario, sky::server::WallClock::now()));
    if (!made) std::abort();
    server = std::move(*made);
    // A region, so snapshots near it carry tiles (and a second subscribe can
    // be answered with a delta).
    sky::weather::Region r;
    r.id = 1;
    r.centerLat_deg = 47.5;
    r.centerLon_deg = 8.5;
    r.sizeX_m = r.sizeY_m = 100'000;
    l.coverage = 0.2;
    r.layers = {l};
    if (!server->weather().submit({{sky::server::SetRegion{r, {}}}, "fuzz", "api"})) std::abort();
    thread = std::thread([this] { server->run(); });
  }
};

Rig& rig() {
  // Never destroyed: the server thread serves until the process ends.
  static Rig* r = new Rig();
  return *r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Rig& r = rig();
  tcp::socket socket(r.clientIo);
  boost::system::error_code ec;
  // A loopback connect can fail for the machine's reasons, not the input's
  // (once in a cold deploy/test run under a load of ~10, after 497 inputs):
  // it is tried again, and if it keeps failing the harness stops saying why
  // and how many descriptors the process holds (a leak of the server's
  // sessions would show there), instead of a bare abort.
  for (int attempt = 0; attempt < 5; ++attempt) {
    if (socket.is_open()) socket.close(ec);
    socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), r.server->port()), ec);
    if (!ec) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100 << attempt));
  }
  if (ec) {
    std::size_t fds = 0;
    for (int fd = 0; fd < 65536; ++fd) fds += ::fcntl(fd, F_GETFD) != -1 ? 1 : 0;
    std::fprintf(stderr, "cannot connect to the fuzzed server after 5 tries: %s (%zu descriptors open)\n",
                 ec.message().c_str(), fds);
    std::abort();
  }
  const timeval deadline{kDeadline_s, 0};
  ::setsockopt(socket.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &deadline, sizeof deadline);
  ::setsockopt(socket.native_handle(), SOL_SOCKET, SO_SNDTIMEO, &deadline, sizeof deadline);
  // Read everything the server sends on a second thread while writing, so a
  // large input cannot deadlock against the server's own writes.
  std::vector<std::uint8_t> received;
  boost::system::error_code readError;
  std::thread reader([&] {
    std::uint8_t buffer[65536];
    for (;;) {
      const std::size_t n = socket.read_some(asio::buffer(buffer), readError);
      if (readError) return;
      received.insert(received.end(), buffer, buffer + n);
    }
  });
  asio::write(socket, asio::buffer(data, size), ec);  // the server may close first: that is fine
  socket.shutdown(tcp::socket::shutdown_send, ec);
  reader.join();
  // The server ends every connection: EOF, or a reset when it closed with
  // input unread. A timeout means it hung.
  if (readError != asio::error::eof && readError != asio::error::connection_reset) {
    std::fprintf(stderr, "server did not close the connection: %s\n", readError.message().c_str());
    std::abort();
  }
  // The first frame is always the Hello (checked when the connection ended
  // in order: a reset may discard what was queued).
  if (readError != asio::error::eof) return 0;
  sky::stream::FrameDecoder decoder;
  decoder.append(received);
  auto first = decoder.next();
  if (!first || !*first) {
    std::fprintf(stderr, "no Hello from the server (%zu bytes)\n", received.size());
    std::abort();
  }
  auto hello = sky::stream::decodeMessage(**first);
  if (!hello || !std::holds_alternative<sky::stream::Hello>(*hello)) std::abort();
  return 0;
}
