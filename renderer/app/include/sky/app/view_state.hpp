// The view a renderer channel draws (CIGI 3.3 View Definition and View
// Control for its --view-id): the frustum's four half-angles, near and far,
// mirroring, and the eyepoint's offset and rotation on the ownship. The
// listener applies packets to it on the io thread (applyViewPacket); the
// render loop composes it onto the ownship pose each frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sky/cigi/packets.hpp"
#include "sky/geo/eyepoint.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::app {

// View Definition's mirror modes (byte 5 bits 6-7).
enum class MirrorMode : std::uint8_t { None = 0, Horizontal = 1, Vertical = 2, Both = 3 };

struct ChannelView {
  std::uint16_t viewId = 0;
  // Starts as the command line's symmetric frustum (--fov and the aspect);
  // each half-angle a View Definition enables replaces its own.
  render::ViewFrustum frustum;
  bool frustumFromHost = false;           // a View Definition set a half-angle
  std::optional<double> near_m, far_m;    // recorded, not used: the clouds have no clip planes
  MirrorMode mirror = MirrorMode::None;
  geo::EyepointOffset eyepoint;           // View Control's enabled fields; 0 until set
  std::uint64_t definitions = 0, controls = 0;  // packets applied
};

enum class ViewPacketOutcome {
  Applied,    // for this channel's view; `unsupported` may name parts it does not draw
  OtherView,  // for another channel's view: ignored
  Rejected,   // for this view, but the result would be no valid view: nothing applied
};

struct ViewUpdate {
  ViewPacketOutcome outcome = ViewPacketOutcome::Applied;
  std::string detail;                    // why, when Rejected
  std::vector<std::string> unsupported;  // accepted, not drawn (orthographic, pixel replication, ...)
};

// Applies a View Definition to `view` when it is for view.viewId: the
// enabled half-angles (the decoder has checked each is finite and within
// +-89.9 deg), near and far, and the mirror mode. Rejected, `view`
// unchanged, when the resulting frustum is not one the renderer draws
// (render::validateInputs: left < right, down < up, each within +-89 deg).
ViewUpdate applyViewPacket(ChannelView& view, const cigi::ViewDefinition& packet);
// Applies a View Control to `view` when it is for view.viewId: the enabled
// offsets (m, body axes) and rotations (deg, relative to the entity).
// A view on an entity other than the ownship (0) is Rejected: this channel
// knows no other entity's pose.
ViewUpdate applyViewPacket(ChannelView& view, const cigi::ViewControl& packet);

// The camera pose of `view` on the ownship pose (geo::eyepointPose).
geo::GeodeticPose viewCamera(const geo::GeodeticPose& ownship, const ChannelView& view);

// Flips a rendered image for the view's mirror mode (Horizontal: left-right,
// Vertical: top-bottom), colour and cloud depth alike.
void mirrorImage(render::Image& image, MirrorMode mode);

}  // namespace sky::app
