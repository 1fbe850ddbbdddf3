// The tool's operator new (tools/large_pages.cpp), linked into this binary
// as into the tool.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "large_pages.h"
#include "thp_probe.h"

namespace {

using ldc::tool::kLargeBlock;

using ldc::test::thp_eligible;
using ldc::test::thp_mode;

TEST(LargePages, LargeBlocksAreAlignedToHugePages) {
  std::vector<char> big(kLargeBlock + 1);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(big.data()) % kLargeBlock, 0u);
  auto arr = std::make_unique<double[]>(3 * kLargeBlock / sizeof(double));
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(arr.get()) % kLargeBlock, 0u);
}

TEST(LargePages, SmallBlocksComeFromMallocAsBefore) {
  // Not a multiple of 2 MiB apart from chance: 64 small blocks cannot all be.
  int aligned = 0;
  std::vector<std::unique_ptr<char[]>> blocks;
  for (int i = 0; i < 64; ++i) {
    blocks.push_back(std::make_unique<char[]>(1000));
    aligned += reinterpret_cast<std::uintptr_t>(blocks.back().get()) % kLargeBlock == 0;
  }
  EXPECT_LT(aligned, 64);
  void* empty = ldc::tool::allocate_block(0);  // a zero-size request still gets a block
  EXPECT_NE(empty, nullptr);
  std::free(empty);
}

TEST(LargePages, LargeBlocksAreAdvisedOntoHugePages) {
  const std::string mode = thp_mode();
  if (mode.empty() || mode.find("[never]") != std::string::npos) GTEST_SKIP() << "transparent huge pages are off";
  std::vector<char> big(4 * kLargeBlock, 1);
  const int eligible = thp_eligible(big.data());
  if (eligible < 0) GTEST_SKIP() << "this kernel's smaps has no THPeligible field";
  EXPECT_EQ(eligible, 1);
}

TEST(LargePages, ABlockTooLargeThrowsBadAlloc) {
  EXPECT_EQ(ldc::tool::allocate_block(std::size_t(1) << 62), nullptr);
  EXPECT_THROW((void)std::vector<char>((std::size_t(1) << 62)), std::bad_alloc);
}

}  // namespace
