// One subscriber's TCP connection: frames in through an incremental decoder,
// out through a bounded Outbox with one write in flight. A protocol error is
// answered with an Error message, after which the session closes; other
// sessions and the server are not affected. Every callback runs inside a
// boundary that turns an exception into closing this session (counted by
// the handler), so no input reaches the io_context's run() as an exception.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "sky/core/result.hpp"
#include "sky/server/area_frames.hpp"
#include "sky/server/outbox.hpp"
#include "sky/server/renderer_info.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class Session;

// What a session needs from its owner. Called on the io_context's thread.
class SessionHandler {
 public:
  // The snapshot answering `request`, at the weather clock of now (or of
  // moments ago, shared with other subscribers of the area: AreaFrames).
  virtual std::shared_ptr<const AreaSnapshot> snapshotFor(const stream::Subscribe& request) = 0;
  // The frame taking a peer that holds `held` (null: nothing) to `now`
  // (encodeWeatherFrame; shared with the peers holding the same).
  virtual std::shared_ptr<const Frame> frameFor(const std::shared_ptr<const AreaSnapshot>& held,
                                                const std::shared_ptr<const AreaSnapshot>& now) = 0;
  // The session has closed its socket and will do no more work.
  virtual void sessionClosed(Session& session) = 0;
  // A frame of `bytes` bytes went out completely.
  virtual void frameSent(std::size_t bytes) = 0;
  // The session is being dropped: its peer stopped reading (a write did not
  // complete within the stall bound).
  virtual void sessionStalled(Session& session) = 0;
  // The session's area or camera report changed.
  virtual void rendererChanged(Session& session) = 0;
  // The peer proposed its estimate of a CIGI host's clock (host_clocks.hpp).
  virtual void hostClockProposed(Session& session, const stream::HostClock& proposal) = 0;
  // The peer asked for the lightning process's flashes over an interval of
  // the weather clock (a renderer drawing frames at its own clock). Returns
  // whether answering it had to compute storm cells (the costly part, which
  // the session's budget counts).
  virtual bool lightningRequested(Session& session, const stream::LightningRequest& request) = 0;
  // The session's input waits for its lightning budget (kLightningCompute*).
  virtual void inputPaused(Session& session) = 0;
  // The peer sent something the stream refuses (a bad frame or message, or a
  // kind clients must not send); the session is closing.
  virtual void protocolRejected(Session& session, const Error& error) = 0;
  // Handling this session's I/O threw (`what`); the session is closing.
  virtual void sessionFailed(Session& session, const std::string& what) = 0;

 protected:
  ~SessionHandler() = default;
};

// Storm-cell computations one session's LightningRequests may cause: a
// burst, then a steady rate. A replay computes once per 10 s of weather
// clock (lightning_service.hpp), so only a peer asking for intervals all
// over the clock meets the bound; its input then waits (TCP backpressure)
// until the budget is back, and the other sessions are served meanwhile.
// At ~6 ms per computation, the rate bounds one peer to ~6 % of a core.
inline constexpr double kLightningComputeBurst = 20;
inline constexpr double kLightningComputeRate_perS = 10;

class Session : public std::enable_shared_from_this<Session> {
 public:
  // handler and log must outlive every call into the session.
  // A write that does not complete within stallTimeout drops the session:
  // the weather it missed is coalesced until then (outbox.hpp), and nobody
  // else waits for it.
  Session(boost::asio::ip::tcp::socket socket, std::uint64_t id, SessionHandler& handler,
          spdlog::logger& log, std::chrono::milliseconds stallTimeout);

  // Sends `hello` (an encoded frame) first and starts reading.
  void start(Frame hello);
  // Instead of start: sends only an Error saying why (e.g. the server is
  // full), then waits briefly for the peer's EOF and closes.
  void refuse(const Error& error);
  // Queues a heartbeat frame, replacing one not yet sent. Ignored once closing.
  void sendHeartbeat(const Frame& heartbeat);
  // The weather changed: fresh weather for each area subscribed (if any)
  // replaces whatever is still waiting to be sent; it goes out as a Delta
  // from what the peer holds for that area when it can, else as a Snapshot.
  void weatherChanged();
  // Queues an event frame (Lightning) for the peer. Ignored once closing.
  void sendEvent(const Frame& frame);
  std::uint64_t droppedEvents() const { return outbox_.droppedEvents(); }
  // The areas the peer subscribed to (none before its first Subscribe).
  std::vector<weather::SphericalCap> areas() const;
  // The host whose clock the peer last proposed for (none before one).
  const std::optional<std::string>& hostClockHost() const { return hostClockHost_; }
  // Closes the socket now, cancelling pending I/O. Idempotent.
  void close();

  std::uint64_t id() const { return id_; }
  const std::string& peer() const { return peer_; }
  // The console's view of this subscriber at wall time `now`.
  RendererInfo info(std::chrono::steady_clock::time_point now) const;

 private:
  enum class State {
    Open,         // reading messages, sending weather
    ErrorQueued,  // an Error is on its way out; input is discarded
    Draining,     // Error sent and our side shut down; waiting for the peer's EOF
    Closed,
  };

  void readMore();
  void onRead(const boost::system::error_code& ec, std::size_t bytes);
  void handleRead(const boost::system::error_code& ec, std::size_t bytes);
  // Handles the complete frames the decoder holds, until it runs out or the
  // session pauses; then reads more unless paused or closed.
  void handleDecoded();
  // One storm-cell computation spent; pauses the input when over budget.
  void spendLightningBudget();
  void onStallTimer(const boost::system::error_code& ec, std::uint64_t generation);
  void handleMessage(const stream::Message& message);
  void protocolError(const Error& error);
  void writeNext();
  Frame weatherFrame(const stream::Subscribe& request);
  void onWritten(const boost::system::error_code& ec);
  void beginDrain();
  // Runs f; an exception closes the session and is reported to the handler.
  template <class F>
  void guarded(const char* where, F&& f);

  boost::asio::ip::tcp::socket socket_;
  boost::asio::steady_timer drainTimer_;
  boost::asio::steady_timer stallTimer_;
  boost::asio::steady_timer pauseTimer_;  // ends a pause of the input
  bool inputPaused_ = false;
  double lightningBudget_ = kLightningComputeBurst;
  std::chrono::steady_clock::time_point lightningBudgetAt_ = std::chrono::steady_clock::now();
  std::chrono::milliseconds stallTimeout_;
  std::uint64_t writeGeneration_ = 0;  // which write the stall timer is watching
  std::uint64_t id_;
  std::string peer_;
  SessionHandler& handler_;
  spdlog::logger& log_;
  State state_ = State::Open;
  // A subscriber sends only small messages: a frame announcing more is
  // refused from its header (framing.hpp).
  stream::FrameDecoder decoder_{stream::kMaxSubscriberFrameBytes};
  // Per area index (Subscribe::areaIndex), each on its own: the latest
  // subscription asked for; what the peer holds, the last snapshot sent (or
  // reached by deltas) with the subscription it answered. A new snapshot of
  // the same subscription goes out as the Delta from it when a delta can say
  // it and is smaller.
  struct Area {
    std::optional<stream::Subscribe> subscription;
    std::shared_ptr<const AreaSnapshot> peerHolds;
  };
  std::array<Area, stream::kMaxAreas> areas_;
  // The newest CameraReport and when it arrived (reports replace each other).
  std::optional<stream::CameraReport> report_;
  std::chrono::steady_clock::time_point reportAt_{};
  bool unknownKindLogged_ = false;
  std::optional<std::string> hostClockHost_;
  std::array<std::uint8_t, 64 * 1024> readBuffer_{};
  Outbox outbox_;
  Frame writing_;  // the frame async_write is sending; untouched until it completes
  bool writeInFlight_ = false;
};

}  // namespace sky::server
