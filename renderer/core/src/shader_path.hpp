// Where the renderer finds its SPIR-V at run time: $SKY_SHADER_DIR, then a
// "shaders" folder next to the executable, then the build tree's directory
// baked in at compile time (SKY_SHADER_BUILD_DIR).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::render {

// Path of the first existing candidate. Error: Io, naming every place tried.
Result<std::filesystem::path> findShader(std::string_view fileName);

// Reads a SPIR-V file. Errors: Io (unreadable), Malformed (size or magic).
Result<std::vector<std::uint32_t>> loadSpirv(const std::filesystem::path& path);

}  // namespace sky::render
