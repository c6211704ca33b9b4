// The shaders' shared pieces (shaders/include/core_common.glsl: camera rays,
// the weather map's projection and ring blend, sphere distances) compiled as
// C++ in double, for the CPU code that must agree with the GPU passes:
// CoreCommon{}.anchorPlane(...). The CPU reference and the atmosphere tables
// include it with the rest of the core instead.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace sky::render {

namespace core_common_glsl {
// The GLSL calls GLM's built-ins unqualified.
using namespace glm;
struct CoreCommon {
  using real = double;
  using real2 = glm::dvec2;
  using real3 = glm::dvec3;
  using real4 = glm::dvec4;
  using real3x3 = glm::dmat3;
  using uint = std::uint32_t;
#define SKY_CORE_CONST static constexpr
#include "core_common.glsl"
#undef SKY_CORE_CONST
};
}  // namespace core_common_glsl

using core_common_glsl::CoreCommon;

}  // namespace sky::render
