// SPIR-V lookup and loading (see shader_path.hpp).
#include "shader_path.hpp"

#include <cstdlib>
#include <fstream>
#include <system_error>

namespace sky::render {

namespace {
constexpr std::uint32_t kSpirvMagic = 0x07230203u;
}

Result<std::filesystem::path> findShader(std::string_view fileName) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("SKY_SHADER_DIR"); dir != nullptr && *dir != '\0')
    candidates.push_back(fs::path(dir) / fileName);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / "shaders" / fileName);
  candidates.push_back(fs::path(SKY_SHADER_BUILD_DIR) / fileName);
  std::string tried;
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c;
    tried += (tried.empty() ? "" : ", ") + c.string();
  }
  return fail(ErrorCode::Io, "shader " + std::string(fileName) + " not found (tried " + tried + ")");
}

Result<std::vector<std::uint32_t>> loadSpirv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return fail(ErrorCode::Io, path.string() + ": cannot open");
  const std::streamsize bytes = in.tellg();
  if (bytes <= 0 || bytes % 4 != 0) return fail(ErrorCode::Malformed, path.string() + ": size is not a multiple of 4");
  std::vector<std::uint32_t> words(std::size_t(bytes) / 4);
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(words.data()), bytes)) return fail(ErrorCode::Io, path.string() + ": read failed");
  if (words[0] != kSpirvMagic) return fail(ErrorCode::Malformed, path.string() + ": not SPIR-V (bad magic)");
  return words;
}

}  // namespace sky::render
