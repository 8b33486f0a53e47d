#include "problem.h"

#include <httplib.h>

#include <nlohmann/json.hpp>

namespace rdm::server {

Problem badRequest(std::string detail, std::string field) {
  return {400, "invalid-request", "Request is malformed", std::move(detail), std::move(field)};
}
Problem invalidField(std::string detail, std::string field) {
  return {422, "invalid-field", "A field is missing, unknown or out of range", std::move(detail),
          std::move(field)};
}
Problem notFound(std::string detail) {
  return {404, "not-found", "No such resource", std::move(detail), {}};
}
Problem conflict(std::string detail, std::string field) {
  return {409, "conflict", "Conflicts with the resource's current state", std::move(detail),
          std::move(field)};
}
Problem internalError() {
  return {
      500, "internal", "Internal server error", "the server could not complete the request", {}};
}

Problem corruptData(std::string detail) {
  return {500, "corrupt-data", "Stored data is damaged", std::move(detail), {}};
}

void writeProblem(httplib::Response& res, const Problem& p, const std::string& instance) {
  nlohmann::json j = {{"type", "https://rdm.invalid/problems/" + p.type},
                      {"title", p.title},
                      {"status", p.status},
                      {"detail", p.detail},
                      {"instance", instance}};
  if (!p.field.empty()) j["field"] = p.field;
  res.status = p.status;
  res.set_content(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n",
                  "application/problem+json");
}

}  // namespace rdm::server
