// One metric in Prometheus's text format, as GET /metrics serves them: its
// HELP and TYPE lines and its value. Shared by every part that adds lines.
#pragma once

#include <cstdint>
#include <string>

namespace sky::server {

inline void appendMetric(std::string& out, const char* name, const char* type, const char* help,
                         std::uint64_t value) {
  out += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n" + name + " " +
         std::to_string(value) + "\n";
}

}  // namespace sky::server
