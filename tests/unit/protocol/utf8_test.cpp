// sky::utf8 (protocol/core): validation against the well-formed byte
// sequences of Unicode table 3-7, replacement by maximal subparts (the
// examples of Unicode 15 section 3.9), and cutting on character boundaries.
// The author-name cut inside a character (issue 18: a 199-byte ASCII author
// plus a two-byte character, cut at 200 bytes, broke every later
// GET /api/events) is the first cut test.
#include <gtest/gtest.h>

#include <string>

#include "sky/core/utf8.hpp"

namespace sky::utf8 {
namespace {

const std::string kFffd(kReplacement);

TEST(Utf8, ValidSequencesAtTheEdgesOfEachRange) {
  for (const char* s : {"", "a", "\x7F", "\xC2\x80", "\xDF\xBF", "\xE0\xA0\x80", "\xED\x9F\xBF", "\xEE\x80\x80",
                        "\xEF\xBF\xBF", "\xF0\x90\x80\x80", "\xF4\x8F\xBF\xBF", "caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x8C\xA7"})
    EXPECT_TRUE(valid(s)) << s;
}

TEST(Utf8, OverlongsSurrogatesAndOutOfRangeAreInvalid) {
  for (const char* s : {"\xC0\x80",          // overlong NUL
                        "\xC1\xBF",          // overlong 0x7F
                        "\xE0\x80\xAF",      // overlong '/'
                        "\xE0\x9F\xBF",      // overlong U+07FF
                        "\xF0\x8F\xBF\xBF",  // overlong U+FFFF
                        "\xED\xA0\x80",      // U+D800, a high surrogate
                        "\xED\xBF\xBF",      // U+DFFF, a low surrogate
                        "\xF4\x90\x80\x80",  // U+110000
                        "\xF5\x80\x80\x80", "\xFF", "\xFE", "\x80", "\xBF"})
    EXPECT_FALSE(valid(s)) << testing::PrintToString(std::string(s));
}

TEST(Utf8, TruncatedSequencesAreInvalid) {
  for (const char* s : {"\xC3", "\xE2\x82", "\xF0\x9F\x8C", "ab\xE2", "\xE2\x82x"})
    EXPECT_FALSE(valid(s)) << testing::PrintToString(std::string(s));
  EXPECT_EQ(validPrefix("ab\xE2\x82"), 2u);
  EXPECT_EQ(validPrefix("abc"), 3u);
}

// An independent reference: decode the bits, then demand the shortest form,
// no surrogate and at most U+10FFFF (RFC 3629 section 3).
bool referenceValid(const unsigned char* b, int n) {
  const int lead = b[0] < 0x80 ? 1 : (b[0] >> 5) == 6 ? 2 : (b[0] >> 4) == 14 ? 3 : (b[0] >> 3) == 30 ? 4 : 0;
  if (lead != n) return false;
  unsigned cp = n == 1 ? b[0] : b[0] & (0x7F >> n);
  for (int i = 1; i < n; ++i) {
    if ((b[i] & 0xC0) != 0x80) return false;
    cp = (cp << 6) | (b[i] & 0x3F);
  }
  const unsigned minimum[] = {0, 0, 0x80, 0x800, 0x10000};
  return cp >= minimum[n] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF);
}

TEST(Utf8, AgreesWithTheReferenceOnEveryShortSequence) {
  unsigned char b[4] = {};
  int mismatches = 0;
  for (unsigned x = 0; x < 0x10000; ++x) {  // every one- and two-byte string
    b[0] = static_cast<unsigned char>(x >> 8);
    b[1] = static_cast<unsigned char>(x);
    const bool expected = referenceValid(b, 2) || (referenceValid(b, 1) && referenceValid(b + 1, 1));
    mismatches += valid({reinterpret_cast<const char*>(b), 2}) != expected;
  }
  for (unsigned x = 0xE00000; x < 0xF00000; ++x) {  // every three-byte string with a three-byte lead
    b[0] = static_cast<unsigned char>(x >> 16), b[1] = static_cast<unsigned char>(x >> 8),
    b[2] = static_cast<unsigned char>(x);
    mismatches += valid({reinterpret_cast<const char*>(b), 3}) != referenceValid(b, 3);
  }
  for (unsigned x = 0xF000; x < 0xF800; ++x) {  // four-byte leads and seconds, a fixed tail
    b[0] = static_cast<unsigned char>(x >> 8), b[1] = static_cast<unsigned char>(x), b[2] = 0x80, b[3] = 0xBF;
    mismatches += valid({reinterpret_cast<const char*>(b), 4}) != referenceValid(b, 4);
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(Utf8, SanitiseReplacesEachMaximalSubpartOnce) {
  // Unicode 15, section 3.9, table 3-8: 61 F1 80 80 E1 80 C2 62 80 63 80 BF 64
  // -> a FFFD FFFD FFFD b FFFD c FFFD FFFD d.
  EXPECT_EQ(sanitise("\x61\xF1\x80\x80\xE1\x80\xC2\x62\x80\x63\x80\xBF\x64"),
            "a" + kFffd + kFffd + kFffd + "b" + kFffd + "c" + kFffd + kFffd + "d");
  // Overlongs and surrogates: every byte is its own subpart (table 3-9, 3-10).
  EXPECT_EQ(sanitise("\xC0\xAF"), kFffd + kFffd);
  EXPECT_EQ(sanitise("\xED\xA0\x80x"), kFffd + kFffd + kFffd + "x");
  EXPECT_EQ(sanitise("/nowhere\xFF"), "/nowhere" + kFffd);
  EXPECT_EQ(sanitise("end\xF0\x9F\x8C"), "end" + kFffd) << "a truncated sequence is one replacement";
  const std::string good = "Z\xC3\xBCrich \xE2\x9B\x85";
  EXPECT_EQ(sanitise(good), good);
  EXPECT_TRUE(valid(sanitise("\xF8\x88\x80\x80\x80\xC3")));
}

TEST(Utf8, CutNeverSplitsACharacter) {
  // The issue 18 author: 199 ASCII bytes and a two-byte character, cut at 200.
  const std::string author = std::string(199, 'a') + "\xC3\xA9";
  EXPECT_EQ(cut(author, 200), std::string(199, 'a'));
  EXPECT_TRUE(valid(cut(author, 200)));
  EXPECT_EQ(cut(author, 201), author);
  // A four-byte character at every offset of the limit.
  const std::string rain = "ab\xF0\x9F\x8C\xA7";
  EXPECT_EQ(cut(rain, 2), "ab");
  EXPECT_EQ(cut(rain, 3), "ab");
  EXPECT_EQ(cut(rain, 4), "ab");
  EXPECT_EQ(cut(rain, 5), "ab");
  EXPECT_EQ(cut(rain, 6), rain);
  EXPECT_EQ(cut(rain, 0), "");
  EXPECT_EQ(cut("abc", 2), "ab");
  // Not UTF-8 (continuation bytes only): cut at the limit, no underflow.
  EXPECT_EQ(cut("\x80\x80\x80\x80\x80\x80", 5).size(), 5u);
  EXPECT_EQ(sanitiseAndCut("\xFF" "abc", 4), kFffd + "a");
  EXPECT_EQ(sanitiseAndCut("\xFF" "abc", 2), "");
}

}  // namespace
}  // namespace sky::utf8
