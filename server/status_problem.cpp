#include "status_problem.h"

#include "rdm/base/log.h"

namespace rdm::server {

Problem problemOf(const Status& status) {
  switch (status.code()) {
    case StatusCode::kInvalidInput:
      return invalidField(status.message(), status.field());
    case StatusCode::kMalformed:
      return {400, "invalid-json", "Request body is not valid JSON", status.message(),
              status.field()};
    case StatusCode::kTooLarge:
      return {413, "body-too-complex", "Request body too complex", status.message(), {}};
    case StatusCode::kNotFound:
      return {404, "not-found", "No such resource", status.message(), status.field()};
    case StatusCode::kConflict:
      return conflict(status.message(), status.field());
    case StatusCode::kBusy:
      return {429, "too-many-jobs", "Too many jobs", status.message(), {}};
    case StatusCode::kNoSpace:
      logEvent(LogLevel::kError, "request_error",
               {{"message", "write failed: " + status.message()}});
      return {507,
              "insufficient-storage",
              "Insufficient storage",
              "the server's data directory is full; nothing was stored",
              {}};
    case StatusCode::kCorrupt:
      logEvent(LogLevel::kError, "request_error", {{"message", status.message()}});
      return corruptData(
          "stored data this request needs fails its checksum or is cut short; "
          "it is not served");
    default:
      logEvent(LogLevel::kError, "request_error", {{"message", status.message()}});
      return internalError();
  }
}

}  // namespace rdm::server
