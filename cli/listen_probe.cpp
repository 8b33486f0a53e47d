#include "listen_probe.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rdm::cli {
namespace {

// errno of binding `a` with SO_REUSEADDR; 0 when it binds.
int bindError(const addrinfo& a) {
  const int fd = ::socket(a.ai_family, a.ai_socktype, a.ai_protocol);
  if (fd < 0) return errno;
  int yes = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  const int err = ::bind(fd, a.ai_addr, a.ai_addrlen) == 0 ? 0 : errno;
  ::close(fd);
  return err;
}

std::string advice(int err, int port) {
  const std::string p = std::to_string(port);
  if (err == EADDRINUSE)
    return " (another process listens on port " + p +
           "; stop it, pick another --port, or --port 0 for a free one)";
  if (err == EACCES) return " (ports below 1024 need privileges; pick --port 1024 or above)";
  if (err == EADDRNOTAVAIL) return " (--bind names no address of this machine)";
  return "";
}

}  // namespace

std::string listenFailureReason(const std::string& address, int port) {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (int e = ::getaddrinfo(address.c_str(), service.c_str(), &hints, &found); e != 0)
    return "cannot resolve '" + address + "': " + gai_strerror(e);
  int err = EADDRNOTAVAIL;  // no address to bind
  for (addrinfo* a = found; a; a = a->ai_next) {
    err = bindError(*a);
    if (err == 0) break;
  }
  ::freeaddrinfo(found);
  return err == 0 ? std::string() : std::strerror(err) + advice(err, port);
}

}  // namespace rdm::cli
