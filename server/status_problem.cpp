#include "status_problem.h"

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

}  // namespace rdm::server
