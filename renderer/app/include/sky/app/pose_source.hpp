// Where a channel's camera comes from, behind one small interface: the
// CIGI host (the pose its listener put in SharedState), FlightGear's native
// FDM stream, ForeFlight lines (both smoothed), or a recorded flight file.
// The channel loop asks a source for the pose to draw now and tells it when
// a frame is done; a new input protocol is one more source and nothing else.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "sky/app/cigi_listener.hpp"
#include "sky/app/fdm_listener.hpp"
#include "sky/app/foreflight_listener.hpp"
#include "sky/app/host_atmosphere.hpp"
#include "sky/app/shared_state.hpp"
#include "sky/flight/flight.hpp"

namespace sky::app {

class PoseSource {
 public:
  virtual ~PoseSource() = default;
  // The pose to draw at `now` (its time of day with it), or none yet.
  virtual std::optional<HostPose> poseAt(SteadyTime now) = 0;
  // frames.jsonl's "source": "cigi", "fdm", "foreflight", "replay".
  virtual const char* source() const = 0;
  // For messages: "CIGI", "FlightGear FDM", "ForeFlight", "flight file".
  virtual const char* name() const = 0;
  // Smoothed sources are sampled at the channel's frame rate, and a frame is
  // drawn for every sample; a CIGI frame is drawn per new host datagram,
  // takes its weather clock and interleave pattern from the host frame, and
  // is idle only once the newest pose is drawn.
  virtual bool smoothed() const = 0;
  // The host's clear air now (Atmosphere Control, FlightGear's visibility).
  virtual HostAtmosphere atmosphere() const = 0;
  // The frame of host frame `hostFrame` is finished.
  virtual void frameDrawn(std::uint32_t hostFrame) { (void)hostFrame; }
  // What the progress line adds (", FlightGear FDM dropped 3"), and the
  // exit summary's line for this source (empty: none).
  virtual std::string progress() const { return {}; }
  virtual std::string summary() const { return {}; }
};

// The CIGI host: poses from SharedState (CigiListener writes them);
// synchronous: frameDrawn sends Start of Frame.
class CigiPoseSource : public PoseSource {
 public:
  CigiPoseSource(SharedState& state, CigiListener& cigi, bool synchronous)
      : state_(state), cigi_(cigi), synchronous_(synchronous) {}
  std::optional<HostPose> poseAt(SteadyTime) override { return state_.pose(); }
  const char* source() const override { return "cigi"; }
  const char* name() const override { return "CIGI"; }
  bool smoothed() const override { return false; }
  HostAtmosphere atmosphere() const override { return state_.atmosphere(); }
  void frameDrawn(std::uint32_t hostFrame) override {
    if (synchronous_) cigi_.frameDrawn(hostFrame);
  }

 private:
  SharedState& state_;
  CigiListener& cigi_;
  bool synchronous_;
};

class FdmPoseSource : public PoseSource {
 public:
  explicit FdmPoseSource(FdmListener& fdm) : fdm_(fdm) {}
  std::optional<HostPose> poseAt(SteadyTime now) override { return fdm_.poseAt(now); }
  const char* source() const override { return "fdm"; }
  const char* name() const override { return "FlightGear FDM"; }
  bool smoothed() const override { return true; }
  HostAtmosphere atmosphere() const override { return fdm_.atmosphere(); }
  std::string progress() const override;
  std::string summary() const override;

 private:
  FdmListener& fdm_;
};

class ForeFlightPoseSource : public PoseSource {
 public:
  // atmosphere: the CIGI host's, if one sends Atmosphere Control (the lines
  // carry none).
  ForeFlightPoseSource(ForeFlightListener& lines, const SharedState& state) : lines_(lines), state_(state) {}
  std::optional<HostPose> poseAt(SteadyTime now) override { return lines_.poseAt(now); }
  const char* source() const override { return "foreflight"; }
  const char* name() const override { return "ForeFlight"; }
  bool smoothed() const override { return true; }
  HostAtmosphere atmosphere() const override { return state_.atmosphere(); }
  std::string progress() const override;
  std::string summary() const override;

 private:
  ForeFlightListener& lines_;
  const SharedState& state_;
};

// A recorded flight (parsed by protocol/flight): the pose at flight time t
// (s from the file's first fix), numbered as host frames by the caller, and
// its time of day when the file says when it was flown (IGC's date, GPX
// and CSV timestamps; source FlightFile), unless `fixedSun`. The headless
// replay steps the flight time itself (poseAtFlightTime); poseAt maps a
// steady clock onto it from `start` at `pace` (flight seconds per second),
// past the end holding the last fix.
class FlightPoseSource : public PoseSource {
 public:
  FlightPoseSource(const flight::Flight& flight, double startFlight_s, SteadyTime start, double pace, bool fixedSun)
      : flight_(flight), startFlight_s_(startFlight_s), start_(start), pace_(pace), fixedSun_(fixedSun) {}
  HostPose poseAtFlightTime(double t_s, std::uint32_t hostFrame) const;
  std::optional<HostPose> poseAt(SteadyTime now) override;
  const char* source() const override { return "replay"; }
  const char* name() const override { return "flight file"; }
  bool smoothed() const override { return true; }
  HostAtmosphere atmosphere() const override { return {}; }

 private:
  const flight::Flight& flight_;
  double startFlight_s_;
  SteadyTime start_;
  double pace_;
  bool fixedSun_;
  std::uint32_t frames_ = 0;
};

}  // namespace sky::app
