// Client-side wording of daemon errors: every message names the server (BakeClient's
// transport errors already do, with the operating system's reason).
#pragma once

#include <string>

namespace rdm::cli {

// `message` is a BakeClient error ("GET /v1/jobs/x: Connection", "HTTP 404: no job 'x'").
std::string describeServerError(const std::string& url, const std::string& message);

}  // namespace rdm::cli
