// The shaders' shared pieces (shaders/include/core_common.glsl: camera rays,
// the weather map's projection and ring blend, sphere distances) compiled as
// C++ in double, for the CPU code that must agree with the GPU passes:
// CoreCommon{}.anchorPlane(...). The CPU reference and the atmosphere tables
// include it with the rest of the core instead.
#pragma once

#include <glm/glm.hpp>

#include "glsl_double.hpp"

namespace sky::render {

namespace core_common_glsl {
// The GLSL calls GLM's built-ins unqualified.
using namespace glm;
struct CoreCommon : GlslDouble {
#define SKY_CORE_CONST static constexpr
#include "core_common.glsl"
#undef SKY_CORE_CONST
};
}  // namespace core_common_glsl

using core_common_glsl::CoreCommon;

}  // namespace sky::render
