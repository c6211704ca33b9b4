// Scenario files from disk (see scenario.hpp).
#include <fstream>
#include <sstream>

#include "sky/server/scenario.hpp"

namespace sky::server {

Result<Scenario> loadScenario(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, path.string() + ": cannot open scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail(ErrorCode::Io, path.string() + ": read failed");
  return parseScenario(text.str(), path.string());
}

}  // namespace sky::server
