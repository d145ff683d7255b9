#include "fieldrig/core/exception_message.h"

#include <gtest/gtest.h>

#include <new>
#include <stdexcept>

namespace fieldrig::core {
namespace {

template <typename Throw>
std::string messageOf(Throw&& throw_it) {
  try {
    throw_it();
  } catch (...) {
    return currentExceptionMessage();
  }
  return "nothing was thrown";
}

TEST(CurrentExceptionMessage, IsOneLineWithoutTrailingBlanks) {
  // cv::Exception's what() spans lines and ends with a line break.
  EXPECT_EQ(
      messageOf([] { throw std::runtime_error("OpenCV(4.6.0) matcher.cpp:12: error:\n(-211)\n"); }),
      "OpenCV(4.6.0) matcher.cpp:12: error: (-211)");
}

TEST(CurrentExceptionMessage, NamesOutOfMemoryAndForeignExceptions) {
  EXPECT_EQ(messageOf([] { throw std::bad_alloc(); }), "out of memory (std::bad_alloc)");
  EXPECT_EQ(messageOf([] { throw 42; }), "an exception that is not a std::exception");
}

}  // namespace
}  // namespace fieldrig::core
