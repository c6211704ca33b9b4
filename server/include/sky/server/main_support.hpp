// What the server's programs (skyshell-weatherd, skyshell-relay) share at
// their edge: the port files scripts and tests wait for, the host name in
// their ids, and the structured log lines on stderr.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "sky/core/result.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

// Writes `port` to `path` via a temporary file and a rename, so a reader
// polling for the file never sees it half written. Errors: Io.
Result<void> writePortFile(const std::filesystem::path& path, std::uint16_t port);

// This machine's host name ("unknown-host" when it cannot be read).
std::string hostName();

// A logger named `name` writing to stderr (journald under systemd) at
// `level` (trace, debug, info, warn, error): a timestamp, the level, then
// "event=... key=value" fields, for grep and log shippers. stdout is left
// to the "listening on" lines scripts wait for.
std::shared_ptr<spdlog::logger> stderrLogger(const std::string& name, const std::string& level);

}  // namespace sky::server
