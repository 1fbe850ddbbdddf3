// The version macros agree with each other and with the .ldc format constant.
// (CMake's project(VERSION) is read from ldc/version.h, so it cannot drift.)
#include <string>

#include <gtest/gtest.h>

#include "ldc/io.h"
#include "ldc/version.h"

TEST(Version, StringSpellsTheThreeNumbers) {
  const std::string expected = std::to_string(LDC_VERSION_MAJOR) + "." + std::to_string(LDC_VERSION_MINOR) +
                               "." + std::to_string(LDC_VERSION_PATCH);
  EXPECT_EQ(expected, LDC_VERSION_STRING);
  EXPECT_EQ(LDC_VERSION, LDC_VERSION_MAJOR * 10000 + LDC_VERSION_MINOR * 100 + LDC_VERSION_PATCH);
}

TEST(Version, FormatVersionIsTheOneSaveWorldWrites) {
  EXPECT_EQ(uint32_t{LDC_FORMAT_VERSION}, ldc::kLdcFormatVersion);
}
