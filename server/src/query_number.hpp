// A number from a query string's value, checked against its range: shared by
// the GET endpoints' query parsers (conditions, conformance, wind). Pure.
#pragma once

#include <charconv>
#include <set>
#include <cmath>
#include <string>
#include <string_view>

#include "sky/core/result.hpp"

namespace sky::server {

inline Result<double> queryNumber(std::string_view key, std::string_view v, double lo, double hi) {
  double x = 0;
  const auto [end, err] = std::from_chars(v.data(), v.data() + v.size(), x);
  if (v.empty() || err != std::errc() || end != v.data() + v.size() || !std::isfinite(x))
    return fail(ErrorCode::Malformed, std::string(key) + ": '" + std::string(v) + "' is not a number");
  if (x < lo || x > hi)
    return fail(ErrorCode::InvalidArgument, std::string(key) + ": " + std::string(v) + " is not in [" +
                                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

// Each key=value pair of a query string, in order, to f(key, value) (a
// Result<void>; the first error ends it): a query over 512 bytes, a pair
// without '=' or a key given twice is refused here, naming it.
template <class F>
Result<void> forEachQueryPair(std::string_view query, F&& f) {
  // Bounded: a query of more than a few keys is not one of ours.
  if (query.size() > 512) return fail(ErrorCode::InvalidArgument, "query: longer than 512 bytes");
  std::set<std::string_view> seen;
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    const std::size_t eq = pair.find('=');
    if (eq == std::string_view::npos) return fail(ErrorCode::Malformed, "query: '" + std::string(pair) + "' is not key=value");
    const std::string_view key = pair.substr(0, eq), value = pair.substr(eq + 1);
    if (!seen.insert(key).second) return fail(ErrorCode::InvalidArgument, std::string(key) + ": given twice");
    if (auto r = f(key, value); !r) return r;
  }
  return {};
}

}  // namespace sky::server
