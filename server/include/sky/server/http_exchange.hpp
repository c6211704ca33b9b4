// One HTTP request to the API, from its bytes to its answer, independent of
// where the bytes come from: the API's connections (http_api.cpp) drive it
// from a socket, the fuzz target and unit tests from a buffer (feed()),
// through the same Beast parser and the same checks. In order, before the
// body is read: the header's size (431), a target and header values that are
// valid UTF-8 (400), Host and Origin (403, http_guard.hpp), the route (404,
// 405), the token for routes that always need it (401), the body's declared
// length against the route's limit (413). Then the endpoint, which answers
// at once or, when the transport can wait (waitWith), later (Next::Wait).
// Nothing thrown inside leaves it: a failure is a 500 (503 out of memory)
// for this request.
#pragma once

#include <functional>
#include <string>
#include <string_view>

// GCC 12 reports a boost::optional inside Beast's parser as maybe
// uninitialized at -O2: a false positive (clang has no such warning).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/beast/core/error.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/string_body.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "sky/server/http_routes.hpp"
#include "sky/server/rejections.hpp"

namespace sky::server {

class HttpApi;

// The request line and header fields, at most (431 past it). Browsers send
// 1-2 KiB; 8 KiB is Beast's default and common among servers.
inline constexpr std::uint32_t kMaxHeader_bytes = 8 * 1024;

class HttpExchange {
 public:
  using Parser = boost::beast::http::request_parser<boost::beast::http::string_body>;
  using Response = boost::beast::http::response<boost::beast::http::string_body>;

  // What the transport does next.
  enum class Next {
    ReadBody,  // read the body into parser() (its limit is set), then afterBody()
    Answer,    // write response(), then close
    Upgrade,   // hand the connection and parser().release() to the console feed
    Close,     // close without an answer (the client left, or was too slow)
    Wait,      // the endpoint answers later, through the LaterAnswer waitWith made: then afterLater()
  };

  explicit HttpExchange(HttpApi& api);

  // Lets endpoints answer later: `later` is called before an endpoint runs
  // (inside afterHeader() or afterBody()) and makes the LaterAnswer it is
  // given (ApiRequest::later), which must lead to afterLater() on the io
  // thread. Without it every endpoint answers at once (feed(), whose caller
  // reads the answer on return).
  void waitWith(std::function<LaterAnswer()> later) { later_ = std::move(later); }

  Parser& parser() { return parser_; }
  Response& response() { return response_; }
  // The header has been parsed.
  Next afterHeader();
  // The body has been read (afterHeader said ReadBody).
  Next afterBody();
  // Reading the header or the body failed with `ec`: an answer (400, 413,
  // 431) or Close (the client left or was too slow).
  Next afterError(boost::beast::error_code ec);
  // The endpoint's later answer (after Next::Wait): `reply` runs under the
  // same guard as an endpoint. Answer.
  Next afterLater(const std::function<HttpReply()>& reply);

  // Feeds a client's bytes through the same steps as the socket does, the
  // end of `bytes` being the client's end of stream. Returns the last step's
  // Next (ReadBody never: an unfinished body is the client leaving, Close).
  Next feed(std::string_view bytes);

 private:
  template <class F>
  Next guarded(F&& step);
  Next headerChecks();
  Next bodyChecks();
  Next answer(HttpReply reply);
  Next refuse(RejectReason reason, int status, std::string_view detail);

  HttpApi& api_;
  Parser parser_;
  Response response_;
  const Route* route_ = nullptr;  // null: a console file or 404
  bool hasToken_ = false;
  std::function<LaterAnswer()> later_;  // empty: answers are given at once
};

}  // namespace sky::server
