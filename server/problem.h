// RFC 9457 problem details: every error the API returns, with the offending field when
// there is one. Handlers return a Problem instead of throwing.
#pragma once

#include <optional>
#include <string>

namespace httplib {
struct Response;
}

namespace rdm::server {

struct Problem {
  int status = 500;
  std::string type;    // short slug, expanded to a URI reference
  std::string title;   // stable per type
  std::string detail;  // this occurrence
  std::string field;   // offending field path, empty when none
};

Problem badRequest(std::string detail, std::string field = {});    // 400 malformed JSON etc.
Problem invalidField(std::string detail, std::string field = {});  // 422 schema / range
Problem notFound(std::string detail);                              // 404
Problem conflict(std::string detail, std::string field = {});      // 409
Problem internalError();                                           // 500, leaks nothing
// 500 `corrupt-data`: stored data this request needs failed its checksum or is torn; it is
// not served (docs/api.md, "Integrity"). `detail` names the resource, never a server path.
Problem corruptData(std::string detail);

void writeProblem(httplib::Response& res, const Problem& problem, const std::string& instance);

}  // namespace rdm::server
