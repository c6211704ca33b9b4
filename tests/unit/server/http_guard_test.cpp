// Host and Origin rules of the HTTP API (http_guard.hpp) and the token's
// constant-time comparison: what a browser sends in the attacks issue 18
// names (DNS rebinding, a foreign page's POST or WebSocket) is refused, what
// the console and the tools send is accepted.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "sky/server/http_guard.hpp"

namespace sky::server {
namespace {

HostRules loopback() { return {8080, "127.0.0.1", {}, {}}; }

TEST(HttpGuard, HostNamesThisServer) {
  const HostRules r = loopback();
  for (const char* ok : {"127.0.0.1:8080", "localhost:8080", "LOCALHOST:8080", "[::1]:8080", "127.0.0.1",
                         "localhost"})
    EXPECT_TRUE(checkHost(ok, r)) << ok;
  // DNS rebinding: the attacker's name now resolves to us; the Host still says its name.
  EXPECT_FALSE(checkHost("evil.example:8080", r));
  EXPECT_FALSE(checkHost("localhost.evil.example:8080", r));
  EXPECT_FALSE(checkHost("127.0.0.1:8081", r)) << "another port";
  EXPECT_FALSE(checkHost("10.0.0.5:8080", r)) << "an address this server is not bound to";
  for (const char* bad : {"", ":8080", "127.0.0.1:", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:80x", "[::1",
                          "a b:8080", "user@127.0.0.1:8080", "127.0.0.1:8080/x"})
    EXPECT_FALSE(checkHost(bad, r)) << "'" << bad << "'";
}

TEST(HttpGuard, ConfiguredNamesAndTheWildcardAddress) {
  HostRules r = loopback();
  r.names = {"Ops-Console"};
  EXPECT_TRUE(checkHost("ops-console:8080", r));
  EXPECT_FALSE(checkHost("ops-console.evil.example:8080", r));
  // Bound to every address: any IP literal reaches it (an address cannot be
  // rebound), names still need configuring.
  r.listenAddress = "0.0.0.0";
  EXPECT_TRUE(checkHost("192.168.1.20:8080", r));
  EXPECT_TRUE(checkHost("[fe80::1]:8080", r));
  EXPECT_FALSE(checkHost("weather.example:8080", r));
  r.listenAddress = "10.1.2.3";
  EXPECT_TRUE(checkHost("10.1.2.3:8080", r));
  EXPECT_FALSE(checkHost("192.168.1.20:8080", r));
}

TEST(HttpGuard, OriginMustBeThisServersPage) {
  const HostRules r = loopback();
  EXPECT_TRUE(checkOrigin("", "127.0.0.1:8080", r)) << "no Origin: not a browser's cross-site request";
  EXPECT_TRUE(checkOrigin("http://127.0.0.1:8080", "127.0.0.1:8080", r));
  EXPECT_TRUE(checkOrigin("http://localhost:8080", "localhost:8080", r));
  EXPECT_FALSE(checkOrigin("http://evil.example", "127.0.0.1:8080", r)) << "a page the operator visits";
  EXPECT_FALSE(checkOrigin("http://evil.example:8080", "evil.example:8080", r)) << "rebinding with a matching Origin";
  EXPECT_FALSE(checkOrigin("http://localhost:8080", "127.0.0.1:8080", r)) << "another origin, though also us";
  EXPECT_FALSE(checkOrigin("http://127.0.0.1:3000", "127.0.0.1:8080", r)) << "another local service's page";
  EXPECT_FALSE(checkOrigin("null", "127.0.0.1:8080", r));
  EXPECT_FALSE(checkOrigin("https://127.0.0.1:8080", "127.0.0.1:8080", r)) << "we serve no https page";
  EXPECT_FALSE(checkOrigin("http://127.0.0.1", "127.0.0.1:8080", r)) << "port 80 is not 8080";
  HostRules extra = r;
  extra.origins = {"http://ops:9000"};
  EXPECT_TRUE(checkOrigin("http://ops:9000", "127.0.0.1:8080", extra));
}

TEST(HttpGuard, ConstantTimeEqualIsEquality) {
  EXPECT_TRUE(constantTimeEqual("Bearer abc", "Bearer abc"));
  EXPECT_FALSE(constantTimeEqual("Bearer abd", "Bearer abc"));
  EXPECT_FALSE(constantTimeEqual("Bearer ab", "Bearer abc"));
  EXPECT_FALSE(constantTimeEqual("Bearer abcd", "Bearer abc"));
  EXPECT_FALSE(constantTimeEqual("", "Bearer abc"));
  EXPECT_TRUE(constantTimeEqual("", ""));
  EXPECT_FALSE(constantTimeEqual("x", ""));
  // Repeating the token must not make a longer guess equal.
  EXPECT_FALSE(constantTimeEqual("abcabc", "abc"));
}

// The time does not depend on where a guess first differs: a guess wrong in
// its first byte and one wrong in its last take the same time within noise
// (medians of many runs; a byte-by-byte compare with an early exit differs
// by the length of the token's loop, ~10x here).
TEST(HttpGuard, ConstantTimeEqualTakesTheSameTimeWhereverItDiffers) {
  const std::string token(4096, 'k');
  std::string early = token, late = token;
  early.front() = 'x';
  late.back() = 'x';
  auto median_ns = [&](const std::string& guess) {
    std::vector<long> t;
    volatile bool sink = false;
    for (int run = 0; run < 301; ++run) {
      const auto a = std::chrono::steady_clock::now();
      for (int i = 0; i < 20; ++i) sink = sink ^ constantTimeEqual(guess, token);
      t.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - a).count());
    }
    std::nth_element(t.begin(), t.begin() + 150, t.end());
    return static_cast<double>(t[150]);
  };
  median_ns(early);  // warm up
  const double e = median_ns(early), l = median_ns(late);
  EXPECT_LT(std::abs(e - l) / std::max(e, l), 0.5) << "early " << e << " ns, late " << l << " ns";
}

}  // namespace
}  // namespace sky::server
