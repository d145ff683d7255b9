// Error and Result: how start-up code and offline tools report bad input.
//
// The live path does not throw (STYLE.md item 5): it marks records and goes on. Code that reads
// files or options returns Result<T>, whose Error names what was wrong and where.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace fieldrig::core {

struct Error {
  std::string message;  // says what and where: "map.csv:12: field 'lat': not a number"
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : state_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<T>(state_); }
  const T& value() const& { return std::get<T>(state_); }
  T&& value() && { return std::get<T>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const Error& error() const { return std::get<Error>(state_); }

 private:
  std::variant<T, Error> state_;
};

// A step that yields nothing but can fail: `return {};` on success, `return Error{…}` otherwise.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }

  const Error& error() const { return *error_; }

 private:
  std::optional<Error> error_;
};

}  // namespace fieldrig::core
