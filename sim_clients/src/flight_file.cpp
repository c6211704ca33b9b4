// Flight files from disk: read the bytes, pick the reader by extension.
#include "sky/sim/flight_file.hpp"

#include <fstream>
#include <sstream>

#include "sky/flight/utf8_text.hpp"

namespace sky::sim {

Result<flight::ParsedFlight> loadFlight(const std::string& path, const flight::ReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, flight::messageText(path) + ": cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  return flight::parseFlight(text.str(), path, options);
}

}  // namespace sky::sim
