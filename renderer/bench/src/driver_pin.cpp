// See driver_pin.hpp.
#include "sky/bench/driver_pin.hpp"

#include <dlfcn.h>

#include <fstream>
#include <set>
#include <string>

namespace sky::bench {

void keepVulkanDriversLoaded() {
  static std::set<std::string> pinned;
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    const auto slash = line.find('/');
    if (slash == std::string::npos) continue;
    const std::string path = line.substr(slash);
    if (path.find("/libvulkan_") == std::string::npos || pinned.count(path)) continue;
    // The handle is never closed: that is the point.
    if (dlopen(path.c_str(), RTLD_NOW | RTLD_NOLOAD) != nullptr) pinned.insert(path);
  }
}

}  // namespace sky::bench
