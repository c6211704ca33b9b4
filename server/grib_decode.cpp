// skyshell-grib-decode: decodes GRIB2 messages with ecCodes for
// skyshell-weatherd, in a process of its own so that a message that crashes
// ecCodes costs this process, not the server (grib_isolated.hpp). Not meant
// to be run by hand: usage FILE FIRST_FIELD_INDEX all|forecast,
// records on file descriptor 3.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sky/server/grib_isolated.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s FILE FIRST_FIELD_INDEX all|forecast (records on fd 3)\n", argv[0]);
    return 2;
  }
  const std::string selection = argv[3];
  if (selection != "all" && selection != "forecast") {
    std::fprintf(stderr, "%s: selection '%s' is not all or forecast\n", argv[0], argv[3]);
    return 2;
  }
  char* end = nullptr;
  const unsigned long long index = std::strtoull(argv[2], &end, 10);
  if (*end || argv[2][0] == '\0') return 2;
  return sky::server::runGribDecoder(argv[1], index,
                                     selection == "all" ? sky::server::GribSelection::All
                                                        : sky::server::GribSelection::Forecast,
                                     3);
}
