#include "fieldrig/core/result.h"

#include <gtest/gtest.h>

#include <string>

namespace fieldrig::core {
namespace {

Result<int> half(int value) {
  if (value % 2 != 0)
    return Error{"odd: " + std::to_string(value)};
  return value / 2;
}

TEST(ResultTest, CarriesValueOrError) {
  const auto good = half(8);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 4);
  const auto bad = half(7);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "odd: 7");
}

Result<void> mustBeEven(int value) {
  if (value % 2 != 0)
    return Error{"odd: " + std::to_string(value)};
  return {};
}

TEST(ResultTest, VoidCarriesSuccessOrError) {
  EXPECT_TRUE(mustBeEven(8).ok());
  EXPECT_TRUE(static_cast<bool>(mustBeEven(0)));
  const auto bad = mustBeEven(3);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "odd: 3");
}

}  // namespace
}  // namespace fieldrig::core
