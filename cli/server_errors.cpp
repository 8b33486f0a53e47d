#include "server_errors.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace rdm::cli {
namespace {

// The HTTP library's transport error names (httplib::to_string(Error)).
constexpr std::array<const char*, 8> kTransportErrors = {
    "Connection",        "BindIPAddress", "Read",    "Write",
    "ConnectionTimeout", "Canceled",      "Unknown", "ExceedRedirectCount"};

// The OS's reason a TCP connection to host:port of `url` fails now; empty when it succeeds.
std::string connectFailure(const std::string& url) {
  std::string rest = url.substr(url.find("//") == std::string::npos ? 0 : url.find("//") + 2);
  rest = rest.substr(0, rest.find('/'));
  const size_t colon = rest.rfind(':');
  const std::string host = colon == std::string::npos ? rest : rest.substr(0, colon);
  const std::string port = colon == std::string::npos ? "80" : rest.substr(colon + 1);
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (int e = getaddrinfo(host.c_str(), port.c_str(), &hints, &found); e != 0)
    return "cannot resolve '" + host + "': " + gai_strerror(e);
  std::string reason = "no address to connect to";
  for (addrinfo* a = found; a; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype, a->ai_protocol);
    if (fd < 0) continue;
    const bool ok = ::connect(fd, a->ai_addr, a->ai_addrlen) == 0;
    reason = ok ? "" : std::strerror(errno);
    ::close(fd);
    if (ok) break;
  }
  freeaddrinfo(found);
  return reason;
}

}  // namespace

std::string describeServerError(const std::string& url, const std::string& message) {
  const size_t colon = message.rfind(": ");
  const std::string tail = colon == std::string::npos ? "" : message.substr(colon + 2);
  for (const char* name : kTransportErrors) {
    if (tail != name) continue;
    const std::string request = message.substr(0, colon);
    std::string cause =
        tail == "Connection" || tail == "ConnectionTimeout" ? connectFailure(url) : std::string();
    if (cause.empty()) {
      cause = tail == "Read"                ? "the connection broke while reading the reply"
              : tail == "Write"             ? "the connection broke while sending the request"
              : tail == "ConnectionTimeout" ? "no answer within the connection timeout"
                                            : "transport error '" + tail + "'";
    }
    return "cannot reach the server at " + url + ": " + cause + " (" + request +
           "). Is `rdm serve` running there?";
  }
  return "server " + url + ": " + message;
}

}  // namespace rdm::cli
