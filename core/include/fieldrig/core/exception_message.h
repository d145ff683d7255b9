#pragma once
// The last resort of every program's main(): what an exception nothing handled says.
#include <string>

namespace fieldrig::core {

// What the exception being handled says, on one line (cv::Exception ends with a line break;
// std::bad_alloc says only "std::bad_alloc"). Call it only inside a catch block.
std::string currentExceptionMessage();

}  // namespace fieldrig::core
