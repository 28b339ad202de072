// Configure-time error values of the drivers module. Opening sockets and bringing up CANopen nodes can
// fail in many environment-specific ways; callers need one readable sentence naming the interface,
// node, object and step, and the RT path must never see an exception — so errors are values here.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace loom::drivers {

// Success, or one human-readable sentence saying what failed and where. Configure-time only (the
// message is a std::string); the RT path reports through flags and codes instead.
class [[nodiscard]] Status {
 public:
  static Status ok() { return Status{}; }
  static Status error(std::string message) { return Status{std::move(message)}; }

  bool is_ok() const { return !message_.has_value(); }
  explicit operator bool() const { return is_ok(); }
  // Empty when ok.
  const std::string& message() const {
    static const std::string kEmpty;
    return message_ ? *message_ : kEmpty;
  }

 private:
  Status() = default;
  explicit Status(std::string m) : message_(std::move(m)) {}
  std::optional<std::string> message_;
};

// A value, or the Status saying why there is none.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)), status_(Status::ok()) {}  // NOLINT: implicit by design
  Result(Status error) : status_(std::move(error)) {}                   // NOLINT: implicit by design

  bool is_ok() const { return value_.has_value(); }
  explicit operator bool() const { return is_ok(); }
  const Status& status() const { return status_; }
  const std::string& error() const { return status_.message(); }
  T& value() { return *value_; }
  const T& value() const { return *value_; }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace loom::drivers
