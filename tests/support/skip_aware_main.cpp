// The main of the test programs whose tests may skip (no Vulkan device, no
// Xvfb, no tshark): a failure always wins, and only a run in which every test
// that ran was skipped exits 77, ctest's SKIP_RETURN_CODE for these programs.
// ctest's SKIP_REGULAR_EXPRESSION would instead report a program skipped as
// soon as one "[  SKIPPED ]" line appears, even when another test failed.
#include <gtest/gtest.h>

namespace {

// ctest SKIP_RETURN_CODE of every program linked with this main.
constexpr int kExitSkipped = 77;

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  if (status != 0) return status;
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  if (unit.skipped_test_count() > 0 && unit.successful_test_count() == 0) return kExitSkipped;
  return 0;
}
