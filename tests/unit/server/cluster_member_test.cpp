// The cluster registry's records (cluster_member.hpp): what a member writes
// reads back the same, and what another process could have put in the
// bucket is refused with a reason naming the field, never thrown.
#include <string>

#include <gtest/gtest.h>

#include "sky/server/cluster_member.hpp"

namespace sky::server {
namespace {

ClusterMember relay() {
  ClusterMember m;
  m.id = "skyshell-relay@site-b:4242";
  m.role = ClusterMember::Role::Relay;
  m.stream = "10.0.0.7:7700";
  m.api = "http://10.0.0.7:8701";
  m.subscribers = 12;
  m.appliedSequence = 981;
  m.stateHash = "0123456789abcdef";
  m.updated_unixMs = 1796536800000;
  return m;
}

TEST(ClusterMember, ARecordReadsBackTheSame) {
  const auto back = decodeClusterMember(clusterMemberJson(relay()).dump());
  ASSERT_TRUE(back) << describe(back.error());
  EXPECT_EQ(back->id, relay().id);
  EXPECT_EQ(back->role, ClusterMember::Role::Relay);
  EXPECT_EQ(back->stream, "10.0.0.7:7700");
  EXPECT_EQ(back->api, "http://10.0.0.7:8701");
  EXPECT_EQ(back->subscribers, 12u);
  EXPECT_EQ(back->appliedSequence, 981u);
  EXPECT_EQ(back->term, 0u);
  EXPECT_EQ(back->stateHash, "0123456789abcdef");
  EXPECT_EQ(back->updated_unixMs, 1796536800000);
  EXPECT_STREQ(roleName(ClusterMember::Role::Leader), "leader");
}

TEST(ClusterMember, WhatAnotherProcessPutIsRefusedNamingTheField) {
  auto refused = [](const std::string& bytes, const std::string& field) {
    const auto r = decodeClusterMember(bytes);
    ASSERT_FALSE(r) << bytes;
    EXPECT_NE(r.error().detail.find(field), std::string::npos) << r.error().detail;
  };
  refused("{not json", "not a JSON object");
  refused("[1, 2]", "not a JSON object");
  auto with = [](const char* key, nlohmann::json value) {
    auto j = clusterMemberJson(relay());
    j[key] = std::move(value);
    return j.dump();
  };
  refused(with("role", "king"), "role");
  refused(with("id", ""), "id");
  refused(with("id", 7), "id");
  refused(with("stream", std::string(kMaxMemberText + 1, 'x')), "stream");
  refused(with("subscribers", -1), "subscribers");
  refused(with("subscribers", 1.5), "subscribers");
  refused(with("term", "3"), "term");
  refused(with("updated_unix_ms", 18446744073709551615ull), "updated_unix_ms");
  auto j = clusterMemberJson(relay());
  j.erase("applied_sequence");
  refused(j.dump(), "applied_sequence");
  const auto big = decodeClusterMember(std::string(kMaxMemberRecord_bytes + 1, ' '));
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code, ErrorCode::TooLarge);
}

}  // namespace
}  // namespace sky::server
