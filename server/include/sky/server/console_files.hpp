// The operator console's static files (server/console/: HTML, CSS, JS), served
// by the HTTP API at GET / and GET /console/<name>. The folder is read once at
// start into memory: only the files found then are served, so no request can
// name a path outside it, and a request never touches the disk.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "sky/core/result.hpp"

namespace sky::server {

struct ConsoleFile {
  std::string contentType;  // "text/html; charset=utf-8", "text/javascript; charset=utf-8", ...
  std::string body;
};

class ConsoleFiles {
 public:
  // Reads every regular file directly in `dir` whose extension has a known
  // content type (.html .css .js .json .svg .png .ico .txt). Io when the
  // folder cannot be read or holds no index.html; TooLarge past 8 MiB in all.
  static Result<ConsoleFiles> load(const std::filesystem::path& dir);

  // The file a GET of `path` (no query) names: "/", "/console" and
  // "/console/" are index.html; "/console/<name>" is that file. Null when it
  // is not a console path or no such file was loaded.
  const ConsoleFile* find(const std::string& path) const;

  const std::filesystem::path& dir() const { return dir_; }
  std::size_t size() const { return files_.size(); }

 private:
  std::filesystem::path dir_;
  std::map<std::string, ConsoleFile> files_;  // by file name
};

// Where the console folder is when no --console-dir is given: `relative`
// (SKY_CONSOLE_RELATIVE_DIR, the install layout's path from the executable's
// folder to the console's, e.g. "../share/skyshell/console") resolved against
// the folder of the running executable (/proc/self/exe). The build tree
// mirrors that layout, so the same default works built and installed.
std::filesystem::path defaultConsoleDir(const std::filesystem::path& relative);

}  // namespace sky::server
