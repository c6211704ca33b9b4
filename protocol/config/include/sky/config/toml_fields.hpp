// Strict reading of TOML input (scenarios, configs): every error names the
// source, line, column and field, unknown keys are errors (a typo is never
// ignored), integers are accepted where a number is expected. Header-only over
// toml++; pure (the caller hands in text and gets values or errors).
#pragma once

#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>

#include <toml++/toml.h>

#include "sky/core/result.hpp"

namespace sky::config {

// Builds error details "file:line:col: field: what" for one source.
class Where {
 public:
  explicit Where(std::string_view sourceName) : source_(sourceName) {}

  tl::unexpected<Error> error(ErrorCode code, const toml::source_region& at, const std::string& field,
                              const std::string& what) const {
    return fail(code, source_ + ":" + std::to_string(at.begin.line) + ":" + std::to_string(at.begin.column) + ": " +
                          field + ": " + what);
  }
  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

inline std::string joinNames(std::initializer_list<std::string_view> names) {
  std::string out;
  for (std::string_view n : names) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

// Rejects keys outside `allowed`.
inline Result<void> onlyKeys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                             const std::string& prefix, const Where& where) {
  for (auto&& [key, node] : table) {
    bool known = false;
    for (std::string_view a : allowed) known = known || key.str() == a;
    if (!known)
      return where.error(ErrorCode::Malformed, node.source(), prefix + std::string(key.str()),
                         "unknown key (expected one of: " + joinNames(allowed) + ")");
  }
  return {};
}

inline Result<const toml::node*> required(const toml::table& table, std::string_view key, const std::string& prefix,
                                          const Where& where) {
  const toml::node* node = table.get(key);
  if (!node) return where.error(ErrorCode::Malformed, table.source(), prefix + std::string(key), "missing (required)");
  return node;
}

// A finite number; TOML integers are accepted (base_m = 1500).
inline Result<double> number(const toml::node& node, const std::string& field, const Where& where) {
  if (const auto* f = node.as_floating_point()) {
    if (!std::isfinite(f->get())) return where.error(ErrorCode::InvalidArgument, node.source(), field, "must be finite");
    return f->get();
  }
  if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
  return where.error(ErrorCode::Malformed, node.source(), field, "must be a number");
}

inline Result<double> number(const toml::table& table, std::string_view key, const std::string& prefix,
                             const Where& where) {
  auto node = required(table, key, prefix, where);
  if (!node) return tl::unexpected(node.error());
  return number(**node, prefix + std::string(key), where);
}

// A number in [lo, hi], or the error says the range.
inline Result<double> numberIn(const toml::table& table, std::string_view key, double lo, double hi,
                               const std::string& prefix, const Where& where) {
  auto v = number(table, key, prefix, where);
  if (!v) return v;
  if (*v < lo || *v > hi)
    return where.error(ErrorCode::InvalidArgument, table.get(key)->source(), prefix + std::string(key),
                       std::to_string(*v) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

inline Result<std::string> string(const toml::table& table, std::string_view key, const std::string& prefix,
                                  const Where& where) {
  auto node = required(table, key, prefix, where);
  if (!node) return tl::unexpected(node.error());
  if (const auto* s = (*node)->as_string()) return s->get();
  return where.error(ErrorCode::Malformed, (*node)->source(), prefix + std::string(key), "must be a string");
}

inline Result<const toml::table*> table(const toml::table& parent, std::string_view key, const std::string& prefix,
                                        const Where& where) {
  auto node = required(parent, key, prefix, where);
  if (!node) return tl::unexpected(node.error());
  if (const auto* t = (*node)->as_table()) return t;
  return where.error(ErrorCode::Malformed, (*node)->source(), prefix + std::string(key), "must be a table");
}

// Parses TOML text; a syntax error names the line and column.
inline Result<toml::table> parseText(std::string_view text, const Where& where) {
  try {
    return toml::parse(text, where.source());
  } catch (const toml::parse_error& e) {
    return where.error(ErrorCode::Malformed, e.source(), "TOML", std::string(e.description()));
  }
}

}  // namespace sky::config
