// Where in the image a change of the weather's tiles shows: the cells of
// the image whose rays may cross the changed tiles' volume (between the
// layer's base and top) or its shadow on the ground, so an interleaved
// renderer keeps its history and lets a redraw replace it there alone (a
// storm cell growing on one side of the view does not redraw the whole
// frame; temporal_plan.cpp).
// Conservative: the volume is sampled on a grid, projected into this frame's
// camera, and the box of the projections, grown by a cell, is marked. Pure
// (no GPU), unit-tested in tests/unit/renderer/history_drop_test.cpp.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "frame_setup.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::render {

// The mask's cells are 2^kHistoryDropCellShift pixels on a side (of the
// cloud pass's image): 8, a few hundred cells at 320x180, and a cell is
// small against what a tile covers on screen.
inline constexpr std::uint32_t kHistoryDropCellShift = 3;

struct HistoryDrop {
  std::uint32_t cellsX = 0, cellsY = 0;
  std::vector<std::uint32_t> cells;  // cellsY rows of cellsX: 1 where the change may show
  std::uint32_t marked = 0;          // cells set
  // The change reaches round the camera (part of its volume in front of it
  // and part behind): every cell is marked.
  bool everywhere = false;
  double fraction() const { return cells.empty() ? 0.0 : double(marked) / double(cells.size()); }
};

// The cells of an image of this setup (its width x height) that the
// rewritten texel rectangles of `field` (WeatherFieldChange::dirty: array
// layer ring * sliceCount + slice, the slice being the layer) may show in.
HistoryDrop historyDrop(const FrameSetup& setup, const WeatherField& field, std::span<const TexelRect> rects);

}  // namespace sky::render
