// The fresh edges' numbering (shaders/include/fresh_edges.glsl) in C++, for
// the planner that sizes the bands and the frame block that dispatches them:
// FreshEdges{}.freshEdgeCount(edges, size).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace sky::render {

namespace fresh_edges_glsl {
// The GLSL calls GLM's built-ins unqualified.
using namespace glm;
struct FreshEdges {
  using uint = std::uint32_t;
#include "fresh_edges.glsl"
};
}  // namespace fresh_edges_glsl

using fresh_edges_glsl::FreshEdges;

}  // namespace sky::render
