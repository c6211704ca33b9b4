// The cells of the image a change of tiles shows in (see history_drop.hpp).
#include "history_drop.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace sky::render {

namespace {

// Grid of points per rectangle edge: the box of the projections of a
// rectangle's grid covers the projection of the rectangle but for the
// bulge of the curved shell between them, which the extra cell covers.
constexpr int kGrid = 5;
// The sun's elevation sine below which a shadow's offset is taken at this
// value: a low sun's shadows are long and faint, and a longer offset would
// mark most of the ground for them.
constexpr double kMinShadowSine = 0.05;

// Screen position (the cloud pass's continuous pixels) of a camera-local
// point, as core_common.glsl's frustumPixel; false when behind the camera.
bool project(const FrameSetup& s, const glm::dvec3& p, glm::dvec2& px) {
  const double z = glm::dot(p, s.camForward);
  if (z <= 1e-6 * glm::length(p)) return false;
  const glm::dvec2 t(glm::dot(p, s.camRight) / z, -glm::dot(p, s.camDown) / z);
  const glm::dvec4 f = s.frustum;
  px = {(t.x - f.x) / (f.y - f.x) * s.rasterWidth, (f.z - t.y) / (f.z - f.w) * s.rasterHeight};
  return true;
}

}  // namespace

HistoryDrop historyDrop(const FrameSetup& setup, const WeatherField& field, std::span<const TexelRect> rects) {
  HistoryDrop d;
  const std::uint32_t cell = 1u << kHistoryDropCellShift;
  d.cellsX = (setup.width + cell - 1) / cell;
  d.cellsY = (setup.height + cell - 1) / cell;
  d.cells.assign(std::size_t(d.cellsX) * d.cellsY, 0);
  if (field.sliceCount == 0 || field.size == 0) return d;
  // The camera frame from the anchor's: camToAnchor's columns are the
  // camera's axes, so its transpose takes anchor vectors to camera ones.
  const glm::dmat3 anchorToCam = glm::transpose(setup.camToAnchor);
  const double R = setup.anchorRadius_m;
  const glm::dvec3 sun = setup.sunDir;
  const bool shadows = sun.z > -kMinShadowSine;
  for (const TexelRect& r : rects) {
    const std::uint32_t ring = r.layer / field.sliceCount, slice = r.layer % field.sliceCount;
    if (ring >= kWeatherRings || slice >= setup.layers.size() || r.width == 0 || r.height == 0) continue;
    const LayerSetup& layer = setup.layers[slice];
    // The rectangle in the gnomonic plane, a texel wider on every side (the
    // map's bilinear filter reaches that far), where the layer's drift has
    // taken it (cloud_pass.glsl: the map is read at the plane point minus
    // the shift).
    const double half = field.halfExtent_m[ring], texel = 2.0 * half / double(field.size);
    const glm::dvec2 lo = glm::dvec2(-half + (double(r.x) - 1.0) * texel, -half + (double(r.y) - 1.0) * texel) +
                          layer.coverageShift_m;
    const glm::dvec2 hi = glm::dvec2(-half + double(r.x + r.width + 1) * texel,
                                     -half + double(r.y + r.height + 1) * texel) +
                          layer.coverageShift_m;
    const double base_m = setup.hGround_m - layer.hBase_m, top_m = setup.hGround_m - layer.hTop_m;
    glm::dvec2 boxLo(1e300), boxHi(-1e300);
    bool front = false, behind = false;
    auto add = [&](const glm::dvec3& p) {
      glm::dvec2 px;
      if (!project(setup, p, px)) {
        behind = true;
        return;
      }
      front = true;
      boxLo = glm::min(boxLo, px);
      boxHi = glm::max(boxHi, px);
    };
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) {
        const glm::dvec2 plane = glm::mix(lo, hi, glm::dvec2(i, j) / double(kGrid - 1));
        const glm::dvec3 dir = glm::normalize(glm::dvec3(plane, R));
        for (const double alt_m : {base_m, top_m}) {
          const glm::dvec3 p = anchorToCam * (dir * (R + alt_m) - setup.camInAnchor_m);
          add(p);
          // Its shadow on the ground, along the key light: over the few
          // hundred km a layer is drawn to, the local vertical is the
          // camera's to within a few degrees, which the extra cell covers.
          if (shadows && alt_m > 0) add(p - sun * (alt_m / std::max(sun.z, kMinShadowSine)));
        }
      }
    if (front && behind) {
      d.everywhere = true;
      break;
    }
    if (!front) continue;
    // Clamped before the conversion: a point just in front of the camera
    // projects arbitrarily far.
    const glm::dvec2 limit(1e6);
    const glm::ivec2 c0 = glm::ivec2(glm::floor(glm::clamp(boxLo, -limit, limit) / double(cell))) - 1;
    const glm::ivec2 c1 = glm::ivec2(glm::floor(glm::clamp(boxHi, -limit, limit) / double(cell))) + 1;
    const int x0 = std::max(c0.x, 0), y0 = std::max(c0.y, 0);
    const int x1 = std::min(c1.x, int(d.cellsX) - 1), y1 = std::min(c1.y, int(d.cellsY) - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) d.cells[std::size_t(y) * d.cellsX + std::size_t(x)] = 1;
  }
  if (d.everywhere) std::fill(d.cells.begin(), d.cells.end(), 1u);
  d.marked = std::uint32_t(std::count(d.cells.begin(), d.cells.end(), 1u));
  return d;
}

}  // namespace sky::render
