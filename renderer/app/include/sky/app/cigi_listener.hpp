// The renderer's CIGI 3.3 endpoint on UDP: takes the ownship pose from each
// host datagram (IG Control + Entity Control for entity 0), with the time of
// day (Celestial Sphere Control, advanced by the host's time line:
// host_clock.hpp), the host's atmosphere (Atmosphere Control), its IG mode
// (Reset/Standby forgets the pose), and the View Definition and View Control
// of this channel's view (other views' are ignored and counted; one that
// would give no valid view is dropped and counted as out of range, the rest
// of its datagram kept), and the host's camera exposure (Skyshell's Component
// Control, for this view or every view) into SharedState and answers with Start of Frame
// (reporting the IG mode), plus a Weather Conditions Response and
// Aerosol Concentration Responses for each Environmental Conditions Request.
// It answers one host only: the one it is told (--cigi-host) or else the
// address of the first sender of a valid host datagram (any port, so a host
// that restarts is answered again). Malformed datagrams and datagrams
// from any other sender are dropped unanswered, counted by reason, and
// logged once per kind; packets the channel does not use are counted by id.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>

#include "sky/app/area_of_interest.hpp"
#include "sky/app/drop_counts.hpp"
#include "sky/app/host_atmosphere.hpp"
#include "sky/app/host_clock.hpp"
#include "sky/app/shared_state.hpp"
#include "sky/weather/air_field.hpp"
#include "sky/weather/query.hpp"
#include "sky/cigi/codec.hpp"

namespace sky::app {

// Liquid water of cloud at density 1, g/m^3 (cumulus 0.3-1, formulas.md).
inline constexpr double kCloudLiquidWater_gpm3 = 0.5;

// The replies to one Environmental Conditions Request from the weather held
// and the host's atmosphere: wind (the layers'), temperature and pressure
// (the atmosphere's sea-level values lapsed by the ISA to the point),
// humidity and visibility at the point (in cloud 100 % and the Koschmieder
// range of its extinction, at most the clear air's; in clear air the
// atmosphere's) (weather bit); each cloud layer 1-3's liquid water there
// (aerosol bit). Pure: the clock comes in as `now`. A point farther than
// kDetailedReach_m from `camera` (the ownship the areas of interest follow)
// is answered from the coarse area's tiles when the view has them: the
// detailed area does not reach it.
std::vector<cigi::Packet> answerConditions(const cigi::EnvironmentalConditionsRequest& request,
                                          const WeatherView& view, std::chrono::steady_clock::time_point now,
                                          const std::optional<geo::Geodetic>& camera = std::nullopt,
                                          const HostAtmosphere& atmosphere = {});

// The weather a datagram's requests are answered from, at `now`: the view
// and the lookups of both its areas (tiles, wind, air), built once for all
// of them (a datagram may carry a thousand requests; each indexing the
// snapshot's tiles again would take a thousand times as long).
struct ConditionsSource {
  ConditionsSource(WeatherView view, std::chrono::steady_clock::time_point now);
  WeatherView view;
  weather::CoverageLookup tiles, coarseTiles;
  weather::WindLookup wind, coarseWind;
  weather::AirField air, coarseAir;
};
std::vector<cigi::Packet> answerConditions(const cigi::EnvironmentalConditionsRequest& request,
                                          const ConditionsSource& source, const std::optional<geo::Geodetic>& camera,
                                          const HostAtmosphere& atmosphere);

// How far from the camera the detailed area always reaches: its radius less
// the distance the camera goes before it is asked again (area_of_interest.hpp).
inline constexpr double kDetailedReach_m = kSubscribeRadius_m - kResubscribeDistance_m;

// The host a CIGI port answers: an address, and a port when one is given
// (without one, any port of that address).
struct CigiHost {
  boost::asio::ip::address address;
  std::optional<unsigned short> port;

  bool matches(const boost::asio::ip::udp::endpoint& from) const {
    return from.address() == address && (!port || from.port() == *port);
  }
};

// Parses --cigi-host: "ADDR" or "ADDR:PORT" for IPv4, "ADDR" or "[ADDR]:PORT"
// for IPv6; PORT in 1..65535. The error does not echo the text.
Result<CigiHost> parseCigiHost(std::string_view text);

class CigiListener {
 public:
  // Binds to address:port (port 0 = ephemeral; see port()). host: the only
  // sender answered; none = the address of the first sender of a valid host
  // datagram becomes it (any port of that address).
  CigiListener(boost::asio::io_context& io, SharedState& state, const std::string& address,
               unsigned short port, std::optional<CigiHost> host = std::nullopt);

  void start();
  void stop();
  unsigned short port() const { return port_; }
  // --utc: the time of day at the host's first datagram, until a Celestial
  // Sphere Control sets one. Call before start().
  void setStartUtc(double utc_s) { clock_ = HostClock(utc_s); }
  // --cigi-sync: synchronous operation. A host datagram is not answered at
  // once (except in Reset/Standby, where no frame is drawn): the render loop
  // calls frameDrawn() once the frame of that host frame is finished, and
  // only then goes Start of Frame (with the answers to its conditions
  // requests), so a host that waits for it is locked to the frames. Call
  // before start().
  void setSynchronous(bool on) { synchronous_ = on; }
  // Synchronous: the frame drawing host frame `hostFrame` is done; sends its
  // Start of Frame to the host. Thread-safe (posted to the io thread).
  void frameDrawn(std::uint32_t hostFrame);

  // Takes one datagram from `from`: the pose into SharedState when it comes
  // from the host, and the reply to send back to `from` (empty: none, the
  // datagram was dropped). What the socket's receive handler calls; public so
  // that tests can drive it without sockets. io thread (or one test thread).
  std::vector<std::uint8_t> handleDatagram(std::span<const std::uint8_t> bytes,
                                           const boost::asio::ip::udp::endpoint& from);

  // Thread-safe.
  std::uint64_t datagramsAccepted() const { return accepted_.load(); }
  std::uint64_t datagramsDropped() const { return drops_.total(); }
  const DropCounts& drops() const { return drops_; }
  // Packets of accepted datagrams the channel does not use, by id.
  const IgnoredPackets& ignored() const { return ignored_; }
  // "Component Control (4) 3, Rate Control (8) 1"; "none".
  std::string ignoredSummary() const;
  // Whether the host holds this IG in Reset/Standby (IG Control's mode).
  bool standby() const { return standby_.load(); }
  // View packets for other channels' views, ignored; parts of this view's
  // View Definitions not drawn (orthographic, pixel replication). Thread-safe.
  std::uint64_t otherViewPackets() const { return otherViewPackets_.load(); }
  std::uint64_t unsupportedViewParts() const { return unsupportedViewParts_.load(); }
  // Camera exposure components applied to this channel, and those for other
  // views (ignored; also counted in otherViewPackets). Thread-safe.
  std::uint64_t hostExposures() const { return hostExposures_.load(); }
  std::uint64_t otherViewExposures() const { return otherViewExposures_.load(); }
  // The host this port answers, once known. Thread-safe.
  std::optional<CigiHost> host() const;

 private:
  void receive();
  void dropped(DropReason reason, const std::string& detail);
  void ignore(std::uint8_t id);
  std::vector<std::uint8_t> startOfFrame(std::uint32_t lastHostFrame, bool standby,
                                         const std::vector<cigi::Packet>& replies);
  template <class ViewPacket>
  void takeView(const ViewPacket& packet, const char* name);
  void takeExposure(const cigi::CameraExposureControl& exposure);

  boost::asio::ip::udp::socket socket_;
  boost::asio::ip::udp::endpoint from_;
  std::array<std::uint8_t, 65536> rx_{};
  SharedState& state_;
  unsigned short port_ = 0;
  std::uint32_t igFrame_ = 0;  // io thread only
  std::atomic<std::uint64_t> accepted_{0};
  std::atomic<std::uint64_t> otherViewPackets_{0}, unsupportedViewParts_{0};
  std::atomic<std::uint64_t> hostExposures_{0}, otherViewExposures_{0};
  std::optional<cigi::CameraExposureControl> loggedExposure_;  // io thread only
  DropCounts drops_;
  std::set<std::string> loggedReasons_;  // io thread only
  IgnoredPackets ignored_;
  std::set<std::uint8_t> loggedIgnored_;  // io thread only
  std::atomic<bool> standby_{false};
  HostTimeline timeline_;  // io thread only
  HostClock clock_;        // io thread only
  bool synchronous_ = false;
  // Synchronous: the answers waiting for their frame's Start of Frame, and
  // where to send it (io thread only). At most one host frame's: a host
  // locked to us sends the next only after it.
  std::vector<cigi::Packet> pendingReplies_;
  std::optional<boost::asio::ip::udp::endpoint> syncHost_;
  mutable std::mutex hostMutex_;         // guards host_ (written by the io thread, read by any)
  std::optional<CigiHost> host_;
};

}  // namespace sky::app
