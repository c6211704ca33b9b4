// The console's static files: what is served at which path, with which
// content type; that nothing outside the folder can be named; and the HTTP
// API routing GET / to them (through HttpApi::handle, as a connection does).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <boost/asio/io_context.hpp>

#include "sky/server/console_files.hpp"
#include "sky/server/http_api.hpp"
#include "sky/server/http_exchange.hpp"
#include "sky/server/live_weather.hpp"

namespace sky::server {
namespace {

namespace fs = std::filesystem;

struct ConsoleDir {
  fs::path dir = fs::temp_directory_path() / ("sky_console_test_" + std::to_string(::getpid()));
  ConsoleDir() {
    fs::remove_all(dir);
    fs::create_directories(dir / "sub");
    write("index.html", "<!doctype html><title>console</title>");
    write("app.js", "export const x = 1;\n");
    write("style.css", "body { margin: 0 }\n");
    write("notes.md", "not a console file type");
    write("sub/inner.js", "in a subfolder");
    std::ofstream(dir.parent_path() / "outside.js") << "secret";
  }
  ~ConsoleDir() {
    fs::remove_all(dir);
    fs::remove(dir.parent_path() / "outside.js");
  }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir / name) << text; }
};

TEST(ConsoleFiles, ServesIndexAtTheRootAndFilesUnderConsole) {
  ConsoleDir d;
  auto files = ConsoleFiles::load(d.dir);
  ASSERT_TRUE(files) << files.error().detail;
  EXPECT_EQ(files->size(), 3u);  // index.html, app.js, style.css
  for (const char* path : {"/", "/console", "/console/", "/console/index.html"}) {
    const ConsoleFile* f = files->find(path);
    ASSERT_NE(f, nullptr) << path;
    EXPECT_EQ(f->contentType, "text/html; charset=utf-8");
    EXPECT_EQ(f->body, "<!doctype html><title>console</title>");
  }
  // ES modules must come as JavaScript, or the browser refuses to run them.
  ASSERT_NE(files->find("/console/app.js"), nullptr);
  EXPECT_EQ(files->find("/console/app.js")->contentType, "text/javascript; charset=utf-8");
  EXPECT_EQ(files->find("/console/style.css")->contentType, "text/css; charset=utf-8");
}

TEST(ConsoleFiles, NamesOutsideTheFolderOrItsTypesAreNotFound) {
  ConsoleDir d;
  auto files = ConsoleFiles::load(d.dir);
  ASSERT_TRUE(files);
  for (const char* path : {"/console/../outside.js", "/console/..%2foutside.js", "/console/sub/inner.js",
                           "/console/notes.md", "/console/missing.js", "/app.js", "/api/state", "/consolex/app.js",
                           "/console//app.js"})
    EXPECT_EQ(files->find(path), nullptr) << path;
}

TEST(ConsoleFiles, AFolderWithoutIndexOrMissingIsAnError) {
  ConsoleDir d;
  fs::remove(d.dir / "index.html");
  auto noIndex = ConsoleFiles::load(d.dir);
  ASSERT_FALSE(noIndex);
  EXPECT_NE(noIndex.error().detail.find("no index.html"), std::string::npos) << noIndex.error().detail;
  auto missing = ConsoleFiles::load(d.dir / "nope");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::Io);
  EXPECT_NE(missing.error().detail.find("nope"), std::string::npos);
}

TEST(ConsoleFiles, DefaultFolderIsRelativeToTheExecutable) {
  const fs::path exe = fs::read_symlink("/proc/self/exe");
  EXPECT_EQ(defaultConsoleDir("../share/skyshell/console"),
            (exe.parent_path() / "../share/skyshell/console").lexically_normal());
}

// Whole requests through the same request handling as the socket path
// (HttpExchange): status and content type of the answer.
struct Served {
  int status = 0;
  std::string contentType;
};
Served serve(HttpApi& api, const std::string& method, const std::string& target) {
  HttpExchange exchange(api);
  const std::string host = "127.0.0.1:" + std::to_string(api.port());
  if (exchange.feed(method + " " + target + " HTTP/1.1\r\nHost: " + host + "\r\n\r\n") != HttpExchange::Next::Answer)
    return {};
  const auto& r = exchange.response();
  return {static_cast<int>(r.result_int()), std::string(r[boost::beast::http::field::content_type])};
}

TEST(ConsoleFiles, TheHttpApiServesThemAndKeepsItsOwnPaths) {
  ConsoleDir d;
  auto files = ConsoleFiles::load(d.dir);
  ASSERT_TRUE(files);
  boost::asio::io_context io;
  Scenario scenario;
  const auto t0 = WallClock::now();
  LiveWeather weather(scenario, t0, [t0] { return t0; }, [] { return std::int64_t{1700000000000}; });
  HttpApiOptions options;
  options.console = std::make_shared<const ConsoleFiles>(std::move(*files));
  auto api = HttpApi::create(io, options, weather, {});
  ASSERT_TRUE(api) << api.error().detail;
  const Served root = serve(**api, "GET", "/");
  EXPECT_EQ(root.status, 200);
  EXPECT_EQ(root.contentType, "text/html; charset=utf-8");
  EXPECT_EQ(serve(**api, "GET", "/console/app.js?v=2").status, 200);
  EXPECT_EQ(serve(**api, "GET", "/console/missing.js").status, 404);
  EXPECT_EQ(serve(**api, "POST", "/").status, 404);
  EXPECT_EQ(serve(**api, "GET", "/api/state").contentType, "application/json");
  // Without console files the root is simply not found.
  auto bare = HttpApi::create(io, HttpApiOptions{}, weather, {});
  ASSERT_TRUE(bare);
  EXPECT_EQ(serve(**bare, "GET", "/").status, 404);
}

}  // namespace
}  // namespace sky::server
