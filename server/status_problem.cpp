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
      return notFound(status.message());
    case StatusCode::kConflict:
      return conflict(status.message(), status.field());
    default:
      return internalError();
  }
}

Problem storageProblem(const Status& status) {
  std::fprintf(stderr, "rdm serve: write failed: %s\n", status.message().c_str());
  if (status.code() != StatusCode::kNoSpace) return internalError();
  return Problem{507,
                 "insufficient-storage",
                 "Insufficient storage",
                 "the server's data directory is full; nothing was stored",
                 {}};
}

}  // namespace rdm::server
