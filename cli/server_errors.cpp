#include "server_errors.h"

namespace rdm::cli {

std::string describeServerError(const std::string& url, const std::string& message) {
  // Transport failures already name the server and the operating system's reason.
  if (message.rfind("cannot reach the server at ", 0) == 0) return message;
  return "server " + url + ": " + message;
}

}  // namespace rdm::cli
