#include "socket_stream.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstring>

namespace rdm::server {
namespace {

void endpoint(const sockaddr_storage& addr, std::string& ip, int& port) {
  char text[INET6_ADDRSTRLEN] = {};
  if (addr.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
    inet_ntop(AF_INET, &a->sin_addr, text, sizeof text);
    port = ntohs(a->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
    inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof text);
    port = ntohs(a->sin6_port);
  }
  ip = text;
}

}  // namespace

PrefixedSocketStream::PrefixedSocketStream(int sock, std::string prefix, int read_timeout_ms,
                                           int write_timeout_ms, Clock::time_point read_deadline,
                                           const std::atomic<bool>& aborted)
    : sock_(sock),
      buf_(std::move(prefix)),
      read_timeout_ms_(read_timeout_ms),
      write_timeout_ms_(write_timeout_ms),
      read_deadline_(read_deadline),
      aborted_(aborted) {}

bool PrefixedSocketStream::waitFor(short events, int timeout_ms, bool reading) const {
  const auto until = Clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!aborted_.load()) {
    const auto now = Clock::now();
    if (now >= until || (reading && now >= read_deadline_)) return false;
    pollfd p{sock_, events, 0};
    const int r = poll(&p, 1, 100);
    if (r > 0) return true;
    if (r < 0 && errno != EINTR) return false;
  }
  return false;
}

bool PrefixedSocketStream::is_readable() const {
  return off_ < buf_.size() || waitFor(POLLIN, read_timeout_ms_, true);
}

bool PrefixedSocketStream::is_writable() const {
  return waitFor(POLLOUT, write_timeout_ms_, false);
}

ssize_t PrefixedSocketStream::read(char* ptr, size_t size) {
  if (off_ >= buf_.size()) {
    if (!waitFor(POLLIN, read_timeout_ms_, true)) return -1;
    buf_.resize(std::max<size_t>(size, 16384));
    off_ = 0;
    ssize_t got;
    do {
      got = recv(sock_, buf_.data(), buf_.size(), 0);
    } while (got < 0 && errno == EINTR);
    if (got <= 0) {
      buf_.clear();
      return got;
    }
    buf_.resize(size_t(got));
  }
  const size_t n = std::min(size, buf_.size() - off_);
  std::memcpy(ptr, buf_.data() + off_, n);
  off_ += n;
  if (off_ == buf_.size()) {
    buf_.clear();
    off_ = 0;
  }
  return ssize_t(n);
}

ssize_t PrefixedSocketStream::write(const char* ptr, size_t size) {
  if (!waitFor(POLLOUT, write_timeout_ms_, false)) return -1;
  ssize_t sent;
  do {
    sent = send(sock_, ptr, size, MSG_NOSIGNAL);
  } while (sent < 0 && errno == EINTR);
  return sent;
}

void PrefixedSocketStream::get_remote_ip_and_port(std::string& ip, int& port) const {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  if (getpeername(sock_, reinterpret_cast<sockaddr*>(&addr), &len) == 0) endpoint(addr, ip, port);
}

void PrefixedSocketStream::get_local_ip_and_port(std::string& ip, int& port) const {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  if (getsockname(sock_, reinterpret_cast<sockaddr*>(&addr), &len) == 0) endpoint(addr, ip, port);
}

}  // namespace rdm::server
