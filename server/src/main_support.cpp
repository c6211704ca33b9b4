// The server programs' shared edge (see main_support.hpp).
#include "sky/server/main_support.hpp"

#include <unistd.h>

#include <fstream>
#include <system_error>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

namespace sky::server {

Result<void> writePortFile(const std::filesystem::path& path, std::uint16_t port) {
  std::filesystem::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << port << '\n';
    out.close();
    if (!out) return fail(ErrorCode::Io, tmp.string() + ": cannot write");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return fail(ErrorCode::Io, path.string() + ": cannot rename into place");
  }
  return {};
}

std::string hostName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "unknown-host";
  return name;
}

std::shared_ptr<spdlog::logger> stderrLogger(const std::string& name, const std::string& level) {
  auto log = std::make_shared<spdlog::logger>(name, std::make_shared<spdlog::sinks::stderr_sink_mt>());
  log->set_level(spdlog::level::from_str(level));
  log->flush_on(spdlog::level::info);
  // Strings that may hold spaces are quoted by the callers ({:?}).
  log->set_pattern("%Y-%m-%dT%H:%M:%S.%e%z level=%l %v");
  return log;
}

}  // namespace sky::server
