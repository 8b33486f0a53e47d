// Error channel for bad input, IO and device failures: a Status carries a code (what kind
// of failure, so callers such as the daemon map it to HTTP without parsing text), the
// offending field path when one field is at fault, and a message that names what is wrong
// (field, offset, file); Expected<T> is a value or a Status.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "rdm/base/check.h"

namespace rdm {

enum class StatusCode {
  kOk,
  kInvalidInput,  // out-of-range or inconsistent input; field() names it when known
  kMalformed,     // input that cannot be parsed at all (JSON syntax, nesting too deep)
  kTooLarge,      // input over a size or memory budget
  kNotFound,
  kConflict,  // valid input that does not apply to the current state
  kBusy,      // a limit on concurrent work is reached; the same request may succeed later
  kIo,        // file system or network
  kNoSpace,   // a write failed for lack of space
  kDevice,    // Vulkan or other device failure
  kCancelled,
  kCorrupt,  // stored data that fails its checksum or is cut short (a damaged or torn file)
  kInternal,
};

class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status error(std::string message) {
    return Status(StatusCode::kInternal, {}, std::move(message));
  }
  static Status error(StatusCode code, std::string message, std::string field = {}) {
    RDM_CHECK(code != StatusCode::kOk);
    return Status(code, std::move(field), std::move(message));
  }
  static Status invalid(std::string field, std::string message) {
    return Status(StatusCode::kInvalidInput, std::move(field), std::move(message));
  }
  // kInvalidInput for one field, in the message form every loader uses: "field 'F': what".
  static Status invalidField(std::string field, const std::string& what) {
    std::string message = "field '" + field + "': " + what;
    return invalid(std::move(field), std::move(message));
  }
  static Status notFound(std::string message, std::string field = {}) {
    return Status(StatusCode::kNotFound, std::move(field), std::move(message));
  }
  static Status conflict(std::string message, std::string field = {}) {
    return Status(StatusCode::kConflict, std::move(field), std::move(message));
  }
  bool ok() const { return !message_.has_value(); }
  StatusCode code() const { return ok() ? StatusCode::kOk : code_; }
  const std::string& field() const { return field_; }
  explicit operator bool() const { return ok(); }
  const std::string& message() const {
    RDM_CHECK(message_.has_value());
    return *message_;
  }

 private:
  Status(StatusCode code, std::string field, std::string message)
      : code_(code), field_(std::move(field)), message_(std::move(message)) {}
  StatusCode code_ = StatusCode::kOk;
  std::string field_;
  std::optional<std::string> message_;
};

template <class T>
class [[nodiscard]] Expected {
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
