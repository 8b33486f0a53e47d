// Error channel for bad input, IO and device failures: a Status carries a message that
// names what is wrong (field, offset, file); Expected<T> is a value or a Status.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "rdm/check.h"

namespace rdm {

class Status {
 public:
  Status() = default;
  static Status error(std::string message) { return Status(std::move(message)); }
  bool ok() const { return !message_.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& message() const {
    RDM_CHECK(message_.has_value());
    return *message_;
  }

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

template <class T>
class Expected {
 public:
  Expected(T value) : data_(std::move(value)) {}  // NOLINT: implicit by design
  Expected(Status status) : data_(std::move(status)) { RDM_CHECK(!std::get<Status>(data_).ok()); }
  bool ok() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return ok(); }
  T& value() {
    RDM_CHECK(ok());
    return std::get<T>(data_);
  }
  const T& value() const {
    RDM_CHECK(ok());
    return std::get<T>(data_);
  }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Status& status() const {
    RDM_CHECK(!ok());
    return std::get<Status>(data_);
  }
  const std::string& error() const { return status().message(); }

 private:
  std::variant<T, Status> data_;
};

}  // namespace rdm
