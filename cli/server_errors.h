// Client-side wording of daemon errors: every message names the server, and a transport
// failure says why the connection failed (the operating system's reason, found by
// connecting once more) instead of the HTTP library's one-word error name.
#pragma once

#include <string>

namespace rdm::cli {

// `message` is a BakeClient error ("GET /v1/jobs/x: Connection", "HTTP 404: no job 'x'").
std::string describeServerError(const std::string& url, const std::string& message);

}  // namespace rdm::cli
