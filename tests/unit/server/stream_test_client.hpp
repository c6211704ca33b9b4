// A blocking-style weather-stream client for the server's socket tests: every
// read has a deadline, so a server bug fails a test instead of hanging it.
#pragma once

#include <array>
#include <chrono>
#include <future>
#include <utility>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace sky::server {

namespace asio = boost::asio;
using asio::ip::tcp;
using namespace std::chrono_literals;

constexpr auto kTimeout = 5s;

class TestClient {
 public:
  explicit TestClient(std::uint16_t port) : socket_(io_) {
    socket_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  }

  void close() {
    boost::system::error_code ignored;
    socket_.close(ignored);
  }
  void sendBytes(const std::vector<std::uint8_t>& bytes) { asio::write(socket_, asio::buffer(bytes)); }
  void send(const stream::Message& m) { sendBytes(stream::encodeFrame(stream::encodeMessage(m))); }

  // The next message; fails with Io "eof" when the server closed the stream.
  Result<stream::Message> read(std::chrono::milliseconds timeout = kTimeout) {
    std::array<std::uint8_t, stream::kFrameHeaderBytes> header{};
    std::vector<std::uint8_t> payload;
    bool done = false;
    boost::system::error_code error;
    asio::async_read(socket_, asio::buffer(header), [&](const boost::system::error_code& ec, std::size_t) {
      if (ec) {
        error = ec;
        done = true;
        return;
      }
      const std::size_t n = (std::size_t{header[0]} << 24) | (std::size_t{header[1]} << 16) |
                            (std::size_t{header[2]} << 8) | header[3];
      payload.resize(n);
      asio::async_read(socket_, asio::buffer(payload), [&](const boost::system::error_code& ec2, std::size_t) {
        error = ec2;
        done = true;
      });
    });
    io_.restart();
    io_.run_for(timeout);
    if (!done) {
      socket_.cancel();
      io_.restart();
      io_.run();
      return fail(ErrorCode::Timeout, "no message within the deadline");
    }
    if (error == asio::error::eof) return fail(ErrorCode::Io, "eof");
    if (error) return fail(ErrorCode::Io, error.message());
    return stream::decodeMessage(payload);
  }

  // The next message of type T, skipping heartbeats, deltas and lightning
  // (unless T is one).
  template <class T>
  Result<T> readNext() {
    for (;;) {
      auto m = read();
      if (!m) return tl::unexpected(m.error());
      if (auto* t = std::get_if<T>(&*m)) return *t;
      // Heartbeats, and deltas of weather changes, come between the others.
      if (!std::holds_alternative<stream::Heartbeat>(*m) && !std::holds_alternative<weather::WeatherDelta>(*m) &&
          !std::holds_alternative<stream::Lightning>(*m))
        return fail(ErrorCode::Malformed, std::string("unexpected ") + stream::kindName(*m));
    }
  }

 private:
  asio::io_context io_;
  tcp::socket socket_;
};

// Runs f on the io_context's thread and returns its result (server state is
// owned by that thread).
template <class F>
auto onIo(asio::io_context& io, F f) {
  std::packaged_task<decltype(f())()> task(std::move(f));
  auto result = task.get_future();
  asio::post(io, [&task] { task(); });
  return result.get();
}

}  // namespace sky::server
