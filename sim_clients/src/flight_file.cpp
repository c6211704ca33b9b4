// Flight files from disk.
#include "sky/sim/flight_file.hpp"

#include <fstream>
#include <sstream>

namespace sky::sim {

Result<flight::Flight> loadFlight(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, path + ": cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  if (ext == "csv" || ext == "CSV") return flight::parseCsv(text.str(), path);
  return fail(ErrorCode::Unsupported, path + ": unknown flight format '." + ext + "' (expected .csv)");
}

}  // namespace sky::sim
