// A number from a query string's value, checked against its range: shared by
// the GET endpoints' query parsers (conditions, conformance). Pure.
#pragma once

#include <charconv>
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

}  // namespace sky::server
