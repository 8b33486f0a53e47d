#include "status_problem.h"

#include <cstdio>

namespace rdm::server {

Problem problemOf(const Status& status) {
  switch (status.code()) {
    case StatusCode::kInvalidInput:
      return status.field().empty() ? sceneProblem(status.message())
                                    : invalidField(status.message(), status.field());
    case StatusCode::kNotFound:
      return notFound(status.message());
    case StatusCode::kConflict:
      return conflict(status.message(), status.field());
    case StatusCode::kInternal:
      // The scene loader reports bad input with the generic code and a field in its text.
      return sceneProblem(status.message());
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
