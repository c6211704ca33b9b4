// The console's static files (see console_files.hpp).
#include "sky/server/console_files.hpp"

#include <array>
#include <fstream>
#include <sstream>
#include <system_error>

namespace sky::server {

namespace {

// The console is a handful of small text files; this bounds what a wrong
// --console-dir (a home folder, say) can make the server hold in memory.
constexpr std::uintmax_t kMaxTotalBytes = 8u << 20;

struct Type {
  const char* extension;
  const char* contentType;
};
constexpr std::array<Type, 8> kTypes = {{
    {".html", "text/html; charset=utf-8"},
    {".css", "text/css; charset=utf-8"},
    {".js", "text/javascript; charset=utf-8"},
    {".json", "application/json"},
    {".svg", "image/svg+xml"},
    {".png", "image/png"},
    {".ico", "image/x-icon"},
    {".txt", "text/plain; charset=utf-8"},
}};

const char* contentTypeOf(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  for (const Type& t : kTypes)
    if (ext == t.extension) return t.contentType;
  return nullptr;
}

}  // namespace

Result<ConsoleFiles> ConsoleFiles::load(const std::filesystem::path& dir) {
  ConsoleFiles out;
  out.dir_ = dir;
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec);
  if (ec) return fail(ErrorCode::Io, "console folder " + dir.string() + ": " + ec.message());
  std::uintmax_t total = 0;
  for (const auto& entry : it) {
    const char* type = contentTypeOf(entry.path());
    if (!type || !entry.is_regular_file(ec)) continue;
    total += entry.file_size(ec);
    if (total > kMaxTotalBytes)
      return fail(ErrorCode::TooLarge, "console folder " + dir.string() + ": over 8 MiB of files");
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) return fail(ErrorCode::Io, "console file " + entry.path().string() + ": cannot read");
    out.files_[entry.path().filename().string()] = {type, text.str()};
  }
  if (!out.files_.count("index.html"))
    return fail(ErrorCode::Io, "console folder " + dir.string() + ": no index.html");
  return out;
}

const ConsoleFile* ConsoleFiles::find(const std::string& path) const {
  std::string name;
  if (path == "/" || path == "/console" || path == "/console/") {
    name = "index.html";
  } else if (path.rfind("/console/", 0) == 0) {
    name = path.substr(9);
  } else {
    return nullptr;
  }
  // Names are keys of the map: "../x" or "a/b" simply are not among them.
  const auto it = files_.find(name);
  return it == files_.end() ? nullptr : &it->second;
}

std::filesystem::path defaultConsoleDir(const std::filesystem::path& relative) {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return relative;
  return (exe.parent_path() / relative).lexically_normal();
}

}  // namespace sky::server
