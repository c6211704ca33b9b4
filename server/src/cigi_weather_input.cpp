// CIGI weather input on UDP (see cigi_weather_input.hpp).
#include "sky/server/cigi_weather_input.hpp"

#include <algorithm>

#include <boost/asio/ip/address.hpp>
#include <spdlog/spdlog.h>

#include "sky/cigi/codec.hpp"

namespace sky::server {

namespace asio = boost::asio;
using asio::ip::udp;

namespace {

// The kind of a reason, for logging each kind once: its text up to the first
// digit (packet indices and values differ between occurrences).
std::string kindOf(const std::string& reason) {
  const auto digit = reason.find_first_of("0123456789");
  return reason.substr(0, std::min<std::size_t>(digit, 80));
}

// Kinds of drop logged once each; the texts are bounded, this is a second
// guard against a log flood.
constexpr std::size_t kMaxLoggedKinds = 256;

}  // namespace

CigiWeatherInput::CigiWeatherInput(asio::io_context& io, WeatherService& weather,
                                   Rejections* rejections, std::shared_ptr<spdlog::logger> log)
    : socket_(io), weather_(weather), rejections_(rejections), log_(std::move(log)), commitTimer_(io) {}

Result<std::unique_ptr<CigiWeatherInput>> CigiWeatherInput::create(asio::io_context& io, const std::string& address,
                                                                   std::uint16_t port, WeatherService& weather,
                                                                   Rejections* rejections,
                                                                   std::shared_ptr<spdlog::logger> log) {
  std::unique_ptr<CigiWeatherInput> in(
      new CigiWeatherInput(io, weather, rejections, log ? log : spdlog::default_logger()));
  boost::system::error_code ec;
  const auto ip = asio::ip::make_address(address, ec);
  if (ec) return fail(ErrorCode::InvalidArgument, "--cigi-listen " + address + ": not an IP address");
  const udp::endpoint at(ip, port);
  in->socket_.open(at.protocol(), ec);
  if (!ec) in->socket_.bind(at, ec);
  if (ec)
    return fail(ErrorCode::Io, "CIGI weather input: cannot bind UDP " + address + ":" + std::to_string(port) + ": " +
                                   ec.message());
  in->port_ = in->socket_.local_endpoint().port();
  in->receive();
  return in;
}

void CigiWeatherInput::close() {
  boost::system::error_code ec;
  socket_.close(ec);
  commitTimer_.cancel();
  if (commitPending_) commitBatch();
}

void CigiWeatherInput::scheduleCommit() {
  if (commitPending_) return;
  commitPending_ = true;
  commitTimer_.expires_after(kCigiCommitBatch);
  commitTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) commitBatch();
  });
}

void CigiWeatherInput::commitBatch() {
  commitPending_ = false;
  try {
    if (auto r = weather_.flush(); !r) {
      ++counters_.commitFailures;
      logOnce("commit failed", "CIGI weather: committing a batch failed (retrying): " + r.error().detail);
      if (socket_.is_open()) scheduleCommit();
      return;
    }
    ++counters_.commits;
  } catch (const std::exception& e) {
    ++counters_.commitFailures;
    if (rejections_) rejections_->count(RejectReason::HandlerFailed);
    logOnce("commit exception", std::string("CIGI weather: committing a batch threw: ") + e.what());
  }
}

CigiWeatherMapper* CigiWeatherInput::mapperFor(const std::string& sender) {
  const auto now = std::chrono::steady_clock::now();
  if (auto it = mappers_.find(sender); it != mappers_.end()) {
    it->second.lastSeen = now;
    return &it->second.mapper;
  }
  if (mappers_.size() >= kMaxCigiSenders)
    std::erase_if(mappers_, [&](const auto& entry) { return now - entry.second.lastSeen > kCigiSenderIdle; });
  if (mappers_.size() >= kMaxCigiSenders) return nullptr;
  Sender& made = mappers_[sender];
  made.lastSeen = now;
  return &made.mapper;
}

void CigiWeatherInput::receive() {
  socket_.async_receive_from(asio::buffer(buffer_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted || !socket_.is_open()) return;
    if (!ec)
      onDatagram(std::span<const std::uint8_t>(buffer_.data(), n),
                 from_.address().to_string() + ":" + std::to_string(from_.port()));
    receive();
  });
}

void CigiWeatherInput::logOnce(const std::string& kind, const std::string& message) {
  if (logged_.size() < kMaxLoggedKinds && logged_.insert(kind).second)
    log_->warn("event=cigi_dropped kind={:?} detail={:?} (further ones of this kind are only counted)", kind, message);
}

void CigiWeatherInput::onDatagram(std::span<const std::uint8_t> bytes, const std::string& sender) {
  ++counters_.datagrams;
  // The boundary of one datagram: whatever handling it throws drops it.
  try {
    handle(bytes, sender);
  } catch (const std::exception& e) {
    if (rejections_) rejections_->count(RejectReason::HandlerFailed);
    logOnce("exception " + kindOf(e.what()),
            "CIGI weather from " + sender + ": dropped a datagram: handling it threw: " + e.what());
  }
}

void CigiWeatherInput::handle(std::span<const std::uint8_t> bytes, const std::string& sender) {
  auto datagram = cigi::decodeDatagram(bytes);
  if (!datagram) {
    ++counters_.malformed;
    if (rejections_) rejections_->count(RejectReason::CigiMalformed);
    logOnce("malformed " + kindOf(datagram.error().detail),
            "CIGI weather from " + sender + ": dropped a datagram: " + datagram.error().detail);
    return;
  }
  if (datagram->direction != cigi::Direction::HostToIg) {
    ++counters_.malformed;
    if (rejections_) rejections_->count(RejectReason::CigiMalformed);
    logOnce("direction", "CIGI weather from " + sender + ": dropped a datagram: it starts with Start of Frame, "
                         "the weather input takes host datagrams only");
    return;
  }
  CigiWeatherMapper* const known = mapperFor(sender);
  if (!known) {
    ++counters_.senderRefused;
    if (rejections_) rejections_->count(RejectReason::CigiRefused);
    logOnce("senders", "CIGI weather from " + sender + ": dropped: already " + std::to_string(kMaxCigiSenders) +
                           " senders (one silent for " + std::to_string(kCigiSenderIdle.count()) +
                           " s is forgotten)");
    return;
  }
  CigiWeatherMapper& mapper = *known;
  auto changes = mapper.map(*datagram);
  if (!changes) {
    ++counters_.rejected;
    if (rejections_) rejections_->count(RejectReason::CigiRefused);
    logOnce("refused " + kindOf(changes.error().detail),
            "CIGI weather from " + sender + ": refused: " + changes.error().detail);
    return;
  }
  if (changes->empty()) {
    ++counters_.unchanged;
    return;
  }
  auto applied = weather_.submitBatched(ChangeRequest{std::move(*changes), "cigi:" + sender, "cigi"});
  if (!applied) {
    ++counters_.rejected;
    if (rejections_) rejections_->count(RejectReason::CigiRefused);
    // The mapper remembered these as sent; forget, so the next resend is
    // mapped (and judged) again.
    mapper.reset();
    logOnce("refused " + kindOf(applied.error().detail),
            "CIGI weather from " + sender + ": refused: " + applied.error().detail);
    return;
  }
  ++counters_.applied;
  scheduleCommit();
  log_->info("event=change_applied source=cigi sender={} sequence={} summary={:?}", sender, applied->sequence,
             applied->summary);
}

}  // namespace sky::server
