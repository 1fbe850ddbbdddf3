// The library's huge-page advice for large fresh arrays (ldc/internal/huge_pages.h).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "ldc/internal/huge_pages.h"
#include "thp_probe.h"

namespace {

using ldc::detail::kHugePageBytes;

TEST(HugePages, ALargeReservedArrayIsAdvisedOntoHugePages) {
  const std::string mode = ldc::test::thp_mode();
  if (mode.empty() || mode.find("[never]") != std::string::npos) GTEST_SKIP() << "transparent huge pages are off";
  std::vector<float> v;
  ldc::detail::reserve_on_huge_pages(v, 4 * kHugePageBytes / sizeof(float));
  v.assign(4 * kHugePageBytes / sizeof(float), 1.0f);
  // The first whole huge page inside the block: only those are advised.
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const auto first = (begin + kHugePageBytes - 1) & ~std::uintptr_t(kHugePageBytes - 1);
  const int eligible = ldc::test::thp_eligible(reinterpret_cast<const void*>(first));
  if (eligible < 0) GTEST_SKIP() << "this kernel's smaps has no THPeligible field";
  EXPECT_EQ(eligible, 1);
  EXPECT_EQ(v.front(), 1.0f);
  EXPECT_EQ(v.back(), 1.0f);
}

TEST(HugePages, SmallNullAndUnalignedBlocksAreLeftAlone) {
  ldc::detail::advise_huge_pages(nullptr, 1u << 30);
  std::vector<char> small(1000, 7);
  ldc::detail::advise_huge_pages(small.data(), small.size());
  ldc::detail::advise_huge_pages(small.data() + 1, small.size() - 1);
  EXPECT_EQ(small[999], 7);
  std::vector<int> none;
  ldc::detail::reserve_on_huge_pages(none, 0);
  EXPECT_TRUE(none.empty());
}

}  // namespace
