// Flight files from disk: read the bytes, pick the reader by extension.
#include "sky/sim/flight_file.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace sky::sim {

Result<flight::ParsedFlight> loadFlight(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, path + ": cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  const auto dot = path.rfind('.');
  const auto slash = path.rfind('/');
  std::string ext = dot == std::string::npos || (slash != std::string::npos && dot < slash) ? "" : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
  if (ext == "csv") return flight::parseCsv(text.str(), path);
  if (ext == "igc") return flight::parseIgc(text.str(), path);
  if (ext == "gpx") return flight::parseGpx(text.str(), path);
  return fail(ErrorCode::Unsupported,
              path + ": unknown flight format '." + ext + "' (expected .csv, .igc or .gpx)");
}

}  // namespace sky::sim
