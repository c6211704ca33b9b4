// shaders/include/precip_streak.glsl compiled as C++ in double, for the CPU
// code and tests that must agree with the near-precipitation pass:
// PrecipStreak{}.streakCoverage(...).
#pragma once

#include <glm/glm.hpp>

#include "glsl_double.hpp"

namespace sky::render {

namespace precip_streak_glsl {
// The GLSL calls GLM's built-ins unqualified.
using namespace glm;
struct PrecipStreak : GlslDouble {
#include "precip_streak.glsl"
};
}  // namespace precip_streak_glsl

using precip_streak_glsl::PrecipStreak;

}  // namespace sky::render
