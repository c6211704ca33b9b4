// A channel's view from CIGI View Definition and View Control (see view_state.hpp).
#include "sky/app/view_state.hpp"

#include <algorithm>
#include <cmath>

namespace sky::app {

namespace {

bool frustumDrawable(const render::ViewFrustum& f) {
  for (double a : {f.left_deg, f.right_deg, f.up_deg, f.down_deg})
    if (!(std::abs(a) < render::kMaxFrustumHalfAngle_deg)) return false;
  return f.left_deg < f.right_deg && f.down_deg < f.up_deg;
}

std::string frustumText(const render::ViewFrustum& f) {
  return "left " + std::to_string(f.left_deg) + " right " + std::to_string(f.right_deg) + " top " +
         std::to_string(f.up_deg) + " bottom " + std::to_string(f.down_deg) + " deg";
}

}  // namespace

ViewUpdate applyViewPacket(ChannelView& view, const cigi::ViewDefinition& p) {
  if (p.viewId != view.viewId) return {ViewPacketOutcome::OtherView, {}, {}};
  render::ViewFrustum f = view.frustum;
  if (p.leftEnable) f.left_deg = p.left_deg;
  if (p.rightEnable) f.right_deg = p.right_deg;
  if (p.topEnable) f.up_deg = p.top_deg;
  if (p.bottomEnable) f.down_deg = p.bottom_deg;
  if (!frustumDrawable(f))
    return {ViewPacketOutcome::Rejected,
            "View Definition for view " + std::to_string(p.viewId) + " gives no drawable frustum (" + frustumText(f) +
                "; needs left < right, bottom < top, each within +-" +
                std::to_string(render::kMaxFrustumHalfAngle_deg) + ")",
            {}};
  ViewUpdate u;
  view.frustumFromHost = view.frustumFromHost || p.leftEnable || p.rightEnable || p.topEnable || p.bottomEnable;
  view.frustum = f;
  if (p.nearEnable) view.near_m = p.near_m;
  if (p.farEnable) view.far_m = p.far_m;
  view.mirror = static_cast<MirrorMode>(p.mirrorMode & 0x03);
  if (p.orthographic) u.unsupported.push_back("orthographic projection (drawn in perspective)");
  if (p.pixelReplication != 0) u.unsupported.push_back("pixel replication");
  ++view.definitions;
  return u;
}

ViewUpdate applyViewPacket(ChannelView& view, const cigi::ViewControl& p) {
  if (p.viewId != view.viewId) return {ViewPacketOutcome::OtherView, {}, {}};
  if (p.entityId != 0)
    return {ViewPacketOutcome::Rejected,
            "View Control for view " + std::to_string(p.viewId) + " on entity " + std::to_string(p.entityId) +
                ": this channel follows the ownship (entity 0) only",
            {}};
  geo::EyepointOffset& e = view.eyepoint;
  if (p.xEnable) e.x_m = p.x_m;
  if (p.yEnable) e.y_m = p.y_m;
  if (p.zEnable) e.z_m = p.z_m;
  if (p.yawEnable) e.yaw_deg = p.yaw_deg;
  if (p.pitchEnable) e.pitch_deg = p.pitch_deg;
  if (p.rollEnable) e.roll_deg = p.roll_deg;
  ++view.controls;
  return {};
}

geo::GeodeticPose viewCamera(const geo::GeodeticPose& ownship, const ChannelView& view) {
  return geo::eyepointPose(ownship, view.eyepoint);
}

void mirrorImage(render::Image& image, MirrorMode mode) {
  if (mode == MirrorMode::None) return;
  const bool flipX = mode == MirrorMode::Horizontal || mode == MirrorMode::Both;
  const bool flipY = mode == MirrorMode::Vertical || mode == MirrorMode::Both;
  const std::size_t w = image.width, h = image.height;
  const bool depth = image.cloudDepth_m.size() == w * h;
  render::Image out = image;
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) {
      const std::size_t to = y * w + x, from = (flipY ? h - 1 - y : y) * w + (flipX ? w - 1 - x : x);
      std::copy_n(image.rgba.begin() + std::ptrdiff_t(4 * from), 4, out.rgba.begin() + std::ptrdiff_t(4 * to));
      if (depth) out.cloudDepth_m[to] = image.cloudDepth_m[from];
    }
  image = std::move(out);
}

}  // namespace sky::app
