// Shared GoogleTest main: with CI=true a test that finds a file or tool missing must fail, not skip
// (see test_support.h).
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
