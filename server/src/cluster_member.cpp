// A cluster member's registry record, written and checked (see
// cluster_member.hpp).
#include "sky/server/cluster_member.hpp"

#include <array>
#include <limits>
#include <utility>

#include "sky/core/utf8.hpp"

namespace sky::server {

namespace {

constexpr std::array<std::pair<ClusterMember::Role, const char*>, 3> kRoles = {{
    {ClusterMember::Role::Leader, "leader"},
    {ClusterMember::Role::Follower, "follower"},
    {ClusterMember::Role::Relay, "relay"},
}};

Error malformed(const std::string& what) { return Error{ErrorCode::Malformed, "cluster member record: " + what}; }

// A text field: present, a string, short, valid UTF-8 (empty allowed).
Result<std::string> text(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_string()) return tl::unexpected(malformed(std::string(key) + ": a string is needed"));
  const auto& s = it->get_ref<const std::string&>();
  if (s.size() > kMaxMemberText)
    return tl::unexpected(malformed(std::string(key) + ": longer than " + std::to_string(kMaxMemberText) + " bytes"));
  if (!utf8::valid(s)) return tl::unexpected(malformed(std::string(key) + ": not UTF-8"));
  return s;
}

// A count field: present, a non-negative integer.
Result<std::uint64_t> count(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number_unsigned())
    return tl::unexpected(malformed(std::string(key) + ": a non-negative integer is needed"));
  return it->get<std::uint64_t>();
}

}  // namespace

const char* roleName(ClusterMember::Role role) {
  for (const auto& [r, name] : kRoles)
    if (r == role) return name;
  return "follower";
}

nlohmann::json clusterMemberJson(const ClusterMember& m) {
  return {{"id", m.id},
          {"role", roleName(m.role)},
          {"stream", m.stream},
          {"api", m.api},
          {"subscribers", m.subscribers},
          {"applied_sequence", m.appliedSequence},
          {"term", m.term},
          {"state_hash", m.stateHash},
          {"updated_unix_ms", m.updated_unixMs}};
}

Result<ClusterMember> decodeClusterMember(std::string_view bytes) {
  if (bytes.size() > kMaxMemberRecord_bytes)
    return fail(ErrorCode::TooLarge, "cluster member record: " + std::to_string(bytes.size()) + " bytes, at most " +
                                         std::to_string(kMaxMemberRecord_bytes));
  const auto j = nlohmann::json::parse(bytes, nullptr, false);
  if (!j.is_object()) return tl::unexpected(malformed("not a JSON object"));
  ClusterMember m;
  auto id = text(j, "id");
  if (!id) return tl::unexpected(id.error());
  if (id->empty()) return tl::unexpected(malformed("id: empty"));
  m.id = std::move(*id);
  auto role = text(j, "role");
  if (!role) return tl::unexpected(role.error());
  bool known = false;
  for (const auto& [r, name] : kRoles)
    if (*role == name) {
      m.role = r;
      known = true;
    }
  if (!known) return tl::unexpected(malformed("role: one of leader, follower, relay is needed"));
  for (auto [key, field] : {std::pair{"stream", &m.stream}, {"api", &m.api}, {"state_hash", &m.stateHash}}) {
    auto v = text(j, key);
    if (!v) return tl::unexpected(v.error());
    *field = std::move(*v);
  }
  for (auto [key, field] : {std::pair{"subscribers", &m.subscribers}, {"applied_sequence", &m.appliedSequence},
                            {"term", &m.term}}) {
    auto v = count(j, key);
    if (!v) return tl::unexpected(v.error());
    *field = *v;
  }
  auto updated = count(j, "updated_unix_ms");
  if (!updated) return tl::unexpected(updated.error());
  if (*updated > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    return tl::unexpected(malformed("updated_unix_ms: out of range"));
  m.updated_unixMs = static_cast<std::int64_t>(*updated);
  return m;
}

}  // namespace sky::server
