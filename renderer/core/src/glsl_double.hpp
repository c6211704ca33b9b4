// The types the shared model's GLSL (shaders/include/) is written in, as
// C++ in double: a class that includes that GLSL as its members derives
// from this (the CPU reference, the atmosphere tables, CoreCommon, the
// tests' harnesses), so the aliases are written once.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace sky::render {

struct GlslDouble {
  using real = double;
  using real2 = glm::dvec2;
  using real3 = glm::dvec3;
  using real4 = glm::dvec4;
  using real3x3 = glm::dmat3;
  using uint = std::uint32_t;
};

}  // namespace sky::render
