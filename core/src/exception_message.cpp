#include "fieldrig/core/exception_message.h"

#include <exception>
#include <new>

namespace fieldrig::core {

std::string currentExceptionMessage() {
  std::string message;
  try {
    throw;
  } catch (const std::bad_alloc&) {
    message = "out of memory (std::bad_alloc)";
  } catch (const std::exception& error) {
    message = error.what();
  } catch (...) {
    message = "an exception that is not a std::exception";
  }
  for (char& c : message) {
    if (c == '\n' || c == '\r')
      c = ' ';
  }
  while (!message.empty() && message.back() == ' ')
    message.pop_back();
  return message;
}

}  // namespace fieldrig::core
