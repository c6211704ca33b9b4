// libFuzzer target: whole HTTP requests (request line, header, body), as a
// client sends them, through the weather server's API: the same Beast parser,
// Host/Origin/token/limit checks, route table and endpoints the socket path
// uses (HttpExchange::feed), on a real HttpApi and LiveWeather that keep
// their state from one input to the next. Every answer must be JSON or text
// in valid UTF-8 with a status the API documents, and never a 500 (an
// exception caught inside is a bug found). Seeds, including the two crashes
// of issue 18: tests/fuzz/corpus/http_request/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string_view>

#include <boost/asio/io_context.hpp>

#include "sky/core/utf8.hpp"
#include "sky/server/http_api.hpp"
#include "sky/server/http_exchange.hpp"

namespace {

struct Api {
  boost::asio::io_context io;
  sky::server::Scenario scenario;
  sky::server::LiveWeather weather{scenario, sky::server::WallClock::now(),
                                   [] { return sky::server::WallClock::now(); }, [] { return std::int64_t{0}; }};
  sky::server::Rejections rejections;
  std::unique_ptr<sky::server::HttpApi> api;

  Api() {
    sky::server::HttpApiOptions options;
    options.token = "fuzz-token";  // the seeds carry it, so applying paths are reached
    options.stations = {{"LIPQ", 45.8275, 13.4722, 12}, {"LJLJ", 46.2237, 14.4576, 388}};
    sky::server::HttpApiHooks hooks;
    hooks.rejections = &rejections;
    auto created = sky::server::HttpApi::create(io, options, weather, hooks);
    if (!created) std::abort();
    api = std::move(*created);
  }
};

bool documented(unsigned status) {
  for (unsigned s : {200u, 400u, 401u, 403u, 404u, 405u, 413u, 426u, 431u, 501u, 503u})
    if (status == s) return true;
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Api api;
  sky::server::HttpExchange exchange(*api.api);
  const auto next = exchange.feed(std::string_view(reinterpret_cast<const char*>(data), size));
  if (next != sky::server::HttpExchange::Next::Answer) return 0;
  const auto& response = exchange.response();
  if (!documented(response.result_int())) std::abort();
  if (!sky::utf8::valid(response.body())) std::abort();
  return 0;
}
