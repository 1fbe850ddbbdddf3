// Status and Result: reading an error's value aborts in every build.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "ldc/status.h"

namespace ldc {
namespace {

Result<int> parse_positive(int v) {
  if (v <= 0) return Status(ErrorCode::kInvalidArgument, "value " + std::to_string(v) + " is not positive");
  return v;
}

TEST(Result, OkResultGivesItsValueEveryWay) {
  Result<std::string> r = std::string("spot");
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(static_cast<bool>(r));
  EXPECT_EQ(r.value(), "spot");
  EXPECT_EQ(*r, "spot");
  EXPECT_EQ(r->size(), 4u);
  EXPECT_EQ(r.value_or("other"), "spot");
  EXPECT_EQ(std::move(r).value(), "spot");
}

TEST(Result, ErrorResultIsFalseAndKeepsItsStatus) {
  Result<int> r = parse_positive(-3);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(static_cast<bool>(r));
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(r.value_or(7), 7);
}

TEST(Result, ValueOrMovesOutOfAnRvalue) {
  Result<std::unique_ptr<int>> r = std::make_unique<int>(5);
  std::unique_ptr<int> p = std::move(r).value_or(nullptr);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(*p, 5);
}

TEST(Result, MadeFromAnOkStatusIsAnInternalError) {
  Result<int> r = Status::ok_status();
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInternal);
}

TEST(ResultDeathTest, ValueOfAnErrorAbortsWithTheMessage) {
  EXPECT_DEATH((void)parse_positive(-3).value(), "value\\(\\) on an error Result: invalid argument: value -3 is not positive");
}

TEST(ResultDeathTest, DereferenceOfAnErrorAborts) {
  const Result<std::string> r = Status(ErrorCode::kIoError, "a.ldc: no such file");
  EXPECT_DEATH((void)*r, "operator\\* on an error Result: i/o error: a.ldc: no such file");
  EXPECT_DEATH((void)r->size(), "operator-> on an error Result");
}

}  // namespace
}  // namespace ldc
