// A number from a query string's value, checked against its range: shared by
// the GET endpoints' query parsers (conditions, conformance, wind, radar). Pure.
#pragma once

#include <charconv>
#include <cmath>
#include <set>
#include <span>
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

// A query of numbers only: each key fills *out, in [lo, hi], and marks
// *seen (two names may share them: a synonym given with its twin is given
// twice). An unknown key is refused, listing `known`.
struct NumberKey {
  std::string_view name;
  bool* seen;
  double* out;
  double lo, hi;
};
inline Result<void> parseNumberKeys(std::string_view query, std::span<const NumberKey> keys, std::string_view known) {
  return forEachQueryPair(query, [&](std::string_view key, std::string_view value) -> Result<void> {
    for (const NumberKey& k : keys)
      if (k.name == key) {
        if (*k.seen) return fail(ErrorCode::InvalidArgument, std::string(key) + ": given twice");
        const auto v = queryNumber(key, value, k.lo, k.hi);
        if (!v) return tl::unexpected(v.error());
        *k.out = *v;
        *k.seen = true;
        return {};
      }
    return fail(ErrorCode::InvalidArgument, "query: unknown key '" + std::string(key) + "' (" + std::string(known) + ")");
  });
}

}  // namespace sky::server
