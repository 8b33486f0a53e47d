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
                                           RateLimit rate, const std::atomic<bool>& aborted)
    : sock_(sock),
      buf_(std::move(prefix)),
      read_timeout_ms_(read_timeout_ms),
      write_timeout_ms_(write_timeout_ms),
      read_deadline_(read_deadline),
      rate_(rate),
      created_(Clock::now()),
      aborted_(aborted) {}

PrefixedSocketStream::Clock::time_point PrefixedSocketStream::rateDeadline(Clock::time_point start,
                                                                           size_t bytes) const {
  const double seconds = rate_.grace_ms / 1000.0 + double(bytes) / rate_.bytes_per_s;
  return start +
         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

bool PrefixedSocketStream::waitFor(short events, int timeout_ms, bool reading) const {
  const auto now0 = Clock::now();
  auto until = now0 + std::chrono::milliseconds(timeout_ms);
  if (reading) {
    until = std::min({until, read_deadline_, rateDeadline(created_, body_read_)});
  } else {
    const auto start = first_write_ == Clock::time_point{} ? now0 : first_write_;
    until = std::min(until, rateDeadline(start, written_));
  }
  while (true) {
    if (aborted_.load()) {
      if (reading) return false;
      if (abort_seen_ == Clock::time_point{}) abort_seen_ = Clock::now();
      until = std::min(until, abort_seen_ + std::chrono::milliseconds(kAbortWriteMs));
    }
    if (Clock::now() >= until) return false;
    pollfd p{sock_, events, 0};
    const int r = poll(&p, 1, 100);
    if (r > 0) return true;
    if (r < 0 && errno != EINTR) return false;
  }
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
    body_read_ += size_t(got);
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
  if (first_write_ == Clock::time_point{}) first_write_ = Clock::now();
  if (!waitFor(POLLOUT, write_timeout_ms_, false)) return -1;
  ssize_t sent;
  do {
    // Never blocks past the deadlines: a partial send returns, and httplib writes the rest.
    sent = send(sock_, ptr, size, MSG_NOSIGNAL | MSG_DONTWAIT);
  } while (sent < 0 && errno == EINTR);
  if (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return 0;
  if (sent > 0) written_ += size_t(sent);
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
