#include "status_problem.h"

#include <cstdio>

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
      std::fprintf(stderr, "rdm serve: write failed: %s\n", status.message().c_str());
      return {507,
              "insufficient-storage",
              "Insufficient storage",
              "the server's data directory is full; nothing was stored",
              {}};
    default:
      std::fprintf(stderr, "rdm serve: %s\n", status.message().c_str());
      return internalError();
  }
}

}  // namespace rdm::server
