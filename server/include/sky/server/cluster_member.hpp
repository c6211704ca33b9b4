// One member of a weather cluster on NATS (a skyshell-weatherd with --nats or
// a skyshell-relay) as it describes itself in the cluster's registry (a KV
// bucket whose keys expire unless put again, see cluster_registry.hpp), and
// as GET /api/cluster and the console show it. The registry is outside
// input: anyone who may publish to the bucket can put anything there, so
// the decoder bounds and checks every field.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"

namespace sky::server {

// The largest record read back (ours are ~300 bytes), and the longest
// id, address or hash in it.
inline constexpr std::size_t kMaxMemberRecord_bytes = 4096;
inline constexpr std::size_t kMaxMemberText = 512;

struct ClusterMember {
  enum class Role { Leader, Follower, Relay };
  std::string id;      // the server's or relay's id (its NATS lease and log name)
  Role role = Role::Follower;
  std::string stream;  // host:port of its weather stream, for renderers
  std::string api;     // http://host:port of its HTTP API, or empty
  std::uint64_t subscribers = 0;      // renderers connected to its stream now
  std::uint64_t appliedSequence = 0;  // the last log entry folded into its weather
  std::uint64_t term = 0;             // the lease revision it leads in (0: not leading)
  std::string stateHash;              // LiveWeather::stateHash, 16 hex digits
  std::int64_t updated_unixMs = 0;    // wall clock of the record, ms since 1970
};

const char* roleName(ClusterMember::Role role);

// The record as JSON (the registry's value and one element of GET
// /api/cluster's "members").
nlohmann::json clusterMemberJson(const ClusterMember& member);
// A registry value read back. Errors: TooLarge (past
// kMaxMemberRecord_bytes), Malformed (not the JSON object of a record, a
// field of the wrong type, a text past kMaxMemberText or not UTF-8, an
// unknown role), each saying which field.
Result<ClusterMember> decodeClusterMember(std::string_view bytes);

}  // namespace sky::server
