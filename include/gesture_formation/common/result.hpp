#pragma once
/// \file
/// \brief `Result<T>`: a value or the reason there is none. The core never logs or throws
/// for bad input; it returns one of these and the caller decides what to say.

#include <optional>
#include <string>
#include <utility>

namespace gesture_formation::common {

/// \brief A value of type T, or a human-readable reason why it could not be produced.
/// Thread safety: a value type; no shared state.
template <class T>
class Result {
 public:
  static Result ok(T value) { return Result(std::move(value), std::string()); }
  static Result fail(std::string reason) { return Result(std::nullopt, std::move(reason)); }

  bool has_value() const { return value_.has_value(); }
  explicit operator bool() const { return value_.has_value(); }
  const T& value() const { return *value_; }
  T& value() { return *value_; }
  const T& operator*() const { return *value_; }
  T& operator*() { return *value_; }
  const T* operator->() const { return &*value_; }
  T* operator->() { return &*value_; }
  /// Empty when the result holds a value.
  const std::string& reason() const { return reason_; }

 private:
  Result(std::optional<T> value, std::string reason) : value_(std::move(value)), reason_(std::move(reason)) {}
  std::optional<T> value_;
  std::string reason_;
};

}  // namespace gesture_formation::common
