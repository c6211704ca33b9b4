// The noise cache on a real folder: the first start generates and writes the
// file, the second loads it without calling the generator and gets the same
// bytes; a damaged, truncated or foreign file is detected, regenerated and
// rewritten; a different seed, size, version or generator misses; a folder
// that cannot be written still gives the right noise and says why. Also the
// file decoder on hand-made bad input.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "sky/render/noise_cache.hpp"

namespace fs = std::filesystem;

namespace sky::render {
namespace {

// A deterministic stand-in generator: bytes from the seed, counted calls.
struct Generator {
  std::uint32_t size = 16, seed = 7;
  int calls = 0;
  std::vector<std::uint8_t> operator()() {
    ++calls;
    std::vector<std::uint8_t> v(std::size_t(size) * size * size);
    std::uint32_t x = seed * 2654435761u + 1;
    for (auto& b : v) {
      x = x * 1664525u + 1013904223u;  // Numerical Recipes LCG
      b = static_cast<std::uint8_t>(x >> 24);
    }
    return v;
  }
};

NoiseKey keyFor(const Generator& g) { return NoiseKey{"test", 1, g.seed, g.size, 1, 0xabcdef}; }

std::vector<std::uint8_t> readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& p, const std::vector<std::uint8_t>& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

class NoiseCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("skyshell-noise-cache-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  CachedNoise get(Generator& g) { return loadOrGenerateNoise(dir_, keyFor(g), std::ref(g)); }
  fs::path dir_;
};

TEST_F(NoiseCacheTest, SecondStartLoadsTheSameBytesWithoutGenerating) {
  Generator g;
  const CachedNoise first = get(g);
  EXPECT_EQ(first.source, NoiseSource::Generated);
  EXPECT_EQ(g.calls, 1);
  EXPECT_TRUE(first.note.empty()) << first.note;
  ASSERT_TRUE(fs::exists(first.path));
  EXPECT_EQ(first.path.parent_path(), dir_);
  EXPECT_EQ(first.texels, Generator{}());

  const CachedNoise second = get(g);
  EXPECT_EQ(second.source, NoiseSource::Loaded);
  EXPECT_EQ(g.calls, 1) << "a second start must not regenerate";
  EXPECT_EQ(second.texels, first.texels);
  EXPECT_EQ(second.path, first.path);
  // No temporary file left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(NoiseCacheTest, DamagedFileIsDetectedAndRegenerated) {
  Generator g;
  const CachedNoise first = get(g);
  const auto good = readBytes(first.path);
  struct Damage {
    const char* name;
    std::vector<std::uint8_t> bytes;
    const char* reason;
  };
  auto flipped = good;
  flipped[flipped.size() / 2] ^= 0x10;  // a texel: only the checksum notices
  auto truncated = good;
  truncated.resize(good.size() - 100);
  auto padded = good;
  padded.push_back(0);
  auto badMagic = good;
  badMagic[0] = 'X';
  for (const Damage& d : {Damage{"flipped texel", flipped, "checksum"}, Damage{"truncated", truncated, "truncated"},
                          Damage{"padded", padded, "padded"}, Damage{"bad magic", badMagic, "magic"},
                          Damage{"empty", {}, "magic"}}) {
    SCOPED_TRACE(d.name);
    writeBytes(first.path, d.bytes);
    const int before = g.calls;
    const CachedNoise again = get(g);
    EXPECT_EQ(again.source, NoiseSource::Regenerated);
    EXPECT_EQ(g.calls, before + 1);
    EXPECT_NE(again.note.find(d.reason), std::string::npos) << again.note;
    EXPECT_EQ(again.texels, first.texels);
    EXPECT_EQ(readBytes(first.path), good) << "the cache file must be rewritten whole";
    EXPECT_EQ(get(g).source, NoiseSource::Loaded);
  }
}

TEST_F(NoiseCacheTest, EveryPartOfTheKeySelectsItsOwnFile) {
  Generator g;
  const CachedNoise base = get(g);
  NoiseKey k = keyFor(g);
  std::vector<NoiseKey> others(6, k);
  others[0].seed = 8;
  others[1].size = 32;
  others[2].generatorVersion = 2;
  others[3].fingerprint = 0x123;  // the generator changed without a version bump
  others[4].kind = "detail";
  others[5].channels = 4;  // RGBA8 texels
  for (const auto& o : others) {
    EXPECT_NE(noiseFileName(o), noiseFileName(k));
    Generator og{o.size, o.seed};
    auto generate = [&] {
      auto v = og();
      v.resize(v.size() * o.channels, 7);
      return v;
    };
    const CachedNoise c = loadOrGenerateNoise(dir_, o, generate);
    EXPECT_EQ(c.source, NoiseSource::Generated) << noiseFileName(o);
    EXPECT_EQ(og.calls, 1);
  }
  // A file renamed to another key's name is refused by its header.
  fs::copy_file(base.path, dir_ / noiseFileName(others[0]), fs::copy_options::overwrite_existing);
  Generator og{16, 8};
  const CachedNoise c = loadOrGenerateNoise(dir_, others[0], std::ref(og));
  EXPECT_EQ(c.source, NoiseSource::Regenerated);
  EXPECT_NE(c.note.find("seed 7, expected 8"), std::string::npos) << c.note;
}

TEST_F(NoiseCacheTest, UnwritableFolderStillGivesTheNoise) {
  Generator g;
  // A regular file where the folder should be: nothing can be created in it.
  std::ofstream(dir_.string()) << "not a folder";
  const CachedNoise c = get(g);
  EXPECT_EQ(c.source, NoiseSource::Generated);
  EXPECT_EQ(c.texels, Generator{}());
  EXPECT_NE(c.note.find("not cached"), std::string::npos) << c.note;
  fs::remove(dir_);
}

TEST_F(NoiseCacheTest, EmptyFolderTurnsCachingOff) {
  Generator g;
  const CachedNoise c = loadOrGenerateNoise({}, keyFor(g), std::ref(g));
  EXPECT_EQ(c.source, NoiseSource::Generated);
  EXPECT_TRUE(c.path.empty());
  EXPECT_EQ(c.texels, Generator{}());
}

TEST(NoiseCacheFile, DecoderNamesWhatIsWrong) {
  const NoiseKey k{"shape", 3, 11, 2, 1, 99};
  const std::vector<std::uint8_t> texels = {1, 2, 3, 4, 5, 6, 7, 8};
  const auto file = encodeNoiseFile(k, texels);
  auto ok = decodeNoiseFile(file, k);
  ASSERT_TRUE(ok) << describe(ok.error());
  EXPECT_EQ(*ok, texels);
  NoiseKey other = k;
  other.generatorVersion = 4;
  auto r = decodeNoiseFile(file, other);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Malformed);
  EXPECT_NE(r.error().detail.find("generator version 3, expected 4"), std::string::npos) << r.error().detail;
  // A header claiming a huge volume is refused before anything is allocated.
  NoiseKey huge = k;
  huge.size = 100000;
  auto h = decodeNoiseFile(encodeNoiseFile(huge, texels), huge);
  ASSERT_FALSE(h);
  EXPECT_NE(h.error().detail.find("size"), std::string::npos) << h.error().detail;
  // Four channels: four bytes per texel.
  NoiseKey rgba = k;
  rgba.channels = 4;
  std::vector<std::uint8_t> rgbaTexels(32, 9);
  auto four = decodeNoiseFile(encodeNoiseFile(rgba, rgbaTexels), rgba);
  ASSERT_TRUE(four) << describe(four.error());
  EXPECT_EQ(four->size(), 32u);
  auto wrongChannels = decodeNoiseFile(encodeNoiseFile(rgba, rgbaTexels), k);
  ASSERT_FALSE(wrongChannels);
  EXPECT_NE(wrongChannels.error().detail.find("channels 4, expected 1"), std::string::npos)
      << wrongChannels.error().detail;
  // Every prefix of a good file is refused, none crashes.
  for (std::size_t n = 0; n < file.size(); ++n)
    EXPECT_FALSE(decodeNoiseFile(std::span(file.data(), n), k)) << n << " bytes";
}

TEST(NoiseCacheFile, DefaultFolderFollowsXdg) {
  const char* oldXdg = std::getenv("XDG_CACHE_HOME");
  const std::string saved = oldXdg ? oldXdg : "";
  setenv("XDG_CACHE_HOME", "/tmp/xdg-cache", 1);
  EXPECT_EQ(defaultCacheDirectory(), fs::path("/tmp/xdg-cache/skyshell"));
  unsetenv("XDG_CACHE_HOME");
  if (const char* home = std::getenv("HOME"); home && *home == '/') {
    EXPECT_EQ(defaultCacheDirectory(), fs::path(home) / ".cache" / "skyshell");
  }
  if (oldXdg) setenv("XDG_CACHE_HOME", saved.c_str(), 1);
}

}  // namespace
}  // namespace sky::render
