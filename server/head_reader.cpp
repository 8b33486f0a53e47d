#include "head_reader.h"

#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include <nlohmann/json.hpp>

namespace rdm::server {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kMaxLineBytes = 8192;  // cpp-httplib 0.11.4's own per-line limit
constexpr const char* kMethods[] = {"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS"};

const char* reason(int status) {
  switch (status) {
    case 408:
      return "Request Timeout";
    case 431:
      return "Request Header Fields Too Large";
    case 501:
      return "Not Implemented";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

void setBlocking(int sock, bool blocking) {
  const int flags = fcntl(sock, F_GETFL, 0);
  fcntl(sock, F_SETFL, blocking ? (flags & ~O_NONBLOCK) : (flags | O_NONBLOCK));
}

bool startsWithNoCase(const std::string& s, size_t pos, const char* prefix) {
  for (size_t i = 0; prefix[i]; ++i) {
    if (pos + i >= s.size() || std::tolower(uint8_t(s[pos + i])) != prefix[i]) return false;
  }
  return true;
}

std::string trim(std::string s) {
  s.erase(0, s.find_first_not_of(" \t"));
  s.erase(s.find_last_not_of(" \t\r") + 1);
  return s;
}

// End of the head (one past the blank line), or npos.
size_t headEnd(const std::string& buf, size_t from) {
  for (size_t i = from; i < buf.size(); ++i) {
    if (buf[i] != '\n') continue;
    if (i >= 1 && buf[i - 1] == '\n') return i + 1;
    if (i >= 2 && buf[i - 1] == '\r' && buf[i - 2] == '\n') return i + 1;
  }
  return std::string::npos;
}

}  // namespace

std::string rawProblemResponse(int status, const std::string& type, const std::string& title,
                               const std::string& detail, const std::string& extra_headers) {
  const nlohmann::json j = {{"type", "https://rdm.invalid/problems/" + type},
                            {"title", title},
                            {"status", status},
                            {"detail", detail}};
  const std::string body = j.dump() + "\n";
  return "HTTP/1.1 " + std::to_string(status) + " " + reason(status) +
         "\r\nContent-Type: application/problem+json\r\nContent-Length: " +
         std::to_string(body.size()) + "\r\nConnection: close\r\n" + extra_headers + "\r\n" + body;
}

HeadReader::HeadReader(HeadLimits limits, Ready ready, Refused refused)
    : limits_(limits), ready_(std::move(ready)), refused_(std::move(refused)) {}

HeadReader::~HeadReader() {
  stop();
}

Status HeadReader::start() {
  epoll_ = epoll_create1(EPOLL_CLOEXEC);
  if (epoll_ < 0) return Status::error(std::string("epoll_create1: ") + std::strerror(errno));
  wake_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_ < 0) return Status::error(std::string("eventfd: ") + std::strerror(errno));
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = wake_;
  if (epoll_ctl(epoll_, EPOLL_CTL_ADD, wake_, &ev) != 0)
    return Status::error(std::string("epoll_ctl: ") + std::strerror(errno));
  thread_ = std::thread([this] { loop(); });
  return {};
}

void HeadReader::add(int sock) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) {
    close(sock);
    return;
  }
  incoming_.push_back({sock, false});
  uint64_t one = 1;
  (void)!write(wake_, &one, sizeof one);
}

void HeadReader::linger(int sock) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) {
    close(sock);
    return;
  }
  incoming_.push_back({sock, true});
  uint64_t one = 1;
  (void)!write(wake_, &one, sizeof one);
}

void HeadReader::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  if (!thread_.joinable()) {  // never started, or start() failed half-way
    if (epoll_ >= 0) close(epoll_);
    if (wake_ >= 0) close(wake_);
    return;
  }
  uint64_t one = 1;
  (void)!write(wake_, &one, sizeof one);
  thread_.join();
  for (auto& [sock, conn] : conns_) close(sock);
  conns_.clear();
  for (auto& [sock, l] : incoming_) close(sock);
  incoming_.clear();
  for (PendingRequest& r : parked_) close(r.sock);
  parked_.clear();
  close(epoll_);
  close(wake_);
}

void HeadReader::watch(int sock, Conn conn) {
  setBlocking(sock, false);
  epoll_event ev{};
  ev.events = EPOLLIN | EPOLLRDHUP;
  ev.data.fd = sock;
  if (epoll_ctl(epoll_, EPOLL_CTL_ADD, sock, &ev) != 0) {
    close(sock);
    return;
  }
  conns_[sock] = std::move(conn);
}

void HeadReader::loop() {
  std::vector<epoll_event> events(256);
  auto last_expire = Clock::now();
  while (true) {
    std::vector<std::pair<int, bool>> fresh;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return;
      fresh.swap(incoming_);
    }
    const auto now = Clock::now();
    for (auto [sock, linger] : fresh) {
      Conn conn;
      conn.accepted = now;
      conn.closing = linger;
      conn.deadline =
          now + std::chrono::milliseconds(linger ? limits_.linger_ms : limits_.timeout_ms);
      if (linger) shutdown(sock, SHUT_WR);
      if (!linger && conns_.size() >= limits_.max_pending) {
        const std::string r = rawProblemResponse(503, "overloaded", "Too many connections",
                                                 "too many connections are sending their "
                                                 "request head; retry later",
                                                 "Retry-After: 1\r\n");
        (void)!send(sock, r.data(), r.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
        close(sock);
        refused_(503);
        continue;
      }
      watch(sock, std::move(conn));
    }
    const int n = epoll_wait(epoll_, events.data(), int(events.size()), 50);
    for (int i = 0; i < n; ++i) {
      const int fd = events[i].data.fd;
      if (fd == wake_) {
        uint64_t v;
        (void)!read(wake_, &v, sizeof v);
        continue;
      }
      if (conns_.count(fd)) onReadable(fd);
    }
    dispatchParked();  // a worker that finished wrote the wake-up (linger)
    if (Clock::now() - last_expire >= std::chrono::milliseconds(50)) {
      expire();  // O(connections): at most 20 times a second
      last_expire = Clock::now();
    }
  }
}

void HeadReader::onReadable(int sock) {
  Conn& conn = conns_[sock];
  char chunk[16384];
  while (true) {
    const ssize_t got = recv(sock, chunk, sizeof chunk, 0);
    if (got == 0 || (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
      drop(sock);  // the peer closed or failed
      return;
    }
    if (got < 0) return;
    if (conn.closing) continue;  // lingering: discard
    const size_t old = conn.buf.size();
    conn.buf.append(chunk, size_t(got));
    const size_t end = headEnd(conn.buf, old >= 2 ? old - 2 : 0);
    if (end != std::string::npos && end <= limits_.max_bytes) return onHead(sock, conn, end);
    if (conn.buf.size() > limits_.max_bytes) {
      return refuse(sock, conn, 431, "header-too-large", "Request header fields too large",
                    "the request head exceeds " + std::to_string(limits_.max_bytes) + " bytes");
    }
  }
}

void HeadReader::onHead(int sock, Conn& conn, size_t head_end) {
  const std::string& buf = conn.buf;
  const size_t sp = buf.find(' ');
  const std::string method = buf.substr(0, std::min(sp, size_t(16)));
  bool known = false;
  for (const char* m : kMethods) known = known || method == m;
  if (!known) {
    return refuse(sock, conn, 501, "method-not-implemented", "Method not implemented",
                  "this server implements GET, HEAD, POST, PATCH, DELETE and OPTIONS");
  }
  PendingRequest req;
  req.sock = sock;
  req.accepted = conn.accepted;
  int fields = 0, ranges = 0;
  size_t pos = buf.find('\n') + 1;
  req.bytes = buf.substr(0, pos);
  while (pos < head_end) {
    size_t eol = buf.find('\n', pos);
    const size_t next = eol + 1;
    const bool blank = next - pos <= 2 && (buf[pos] == '\n' || buf[pos] == '\r');
    if (!blank) {
      if (++fields > limits_.max_fields || next - pos > kMaxLineBytes) {
        return refuse(sock, conn, 431, "header-too-large", "Request header fields too large",
                      "at most " + std::to_string(limits_.max_fields) + " header fields of " +
                          std::to_string(kMaxLineBytes) + " bytes each");
      }
      if (startsWithNoCase(buf, pos, "transfer-encoding:")) req.has_body = true;
      if (startsWithNoCase(buf, pos, "content-length:")) {
        const std::string value = trim(buf.substr(pos + 15, eol - pos - 15));
        if (value.find_first_not_of('0') != std::string::npos) req.has_body = true;
        req.body_bytes = size_t(std::strtoull(value.c_str(), nullptr, 10));
      }
      if (startsWithNoCase(buf, pos, "range:")) {
        ++ranges;
        req.range = trim(buf.substr(pos + 6, eol - pos - 6));
        pos = next;
        continue;
      }
    }
    req.bytes.append(buf, pos, next - pos);
    pos = next;
  }
  if (ranges != 1) req.range.reset();  // RFC 9110 14.2: a server may ignore Range
  req.bytes.append(buf, head_end, std::string::npos);
  epoll_ctl(epoll_, EPOLL_CTL_DEL, sock, nullptr);
  conns_.erase(sock);
  setBlocking(sock, true);
  if (parked_.empty() && ready_(req)) return;
  if (parked_.size() >= limits_.max_pending) return answerBusy(req);
  parked_.push_back(std::move(req));
}

void HeadReader::answerBusy(PendingRequest& req) {
  refused_(503);
  const std::string r =
      rawProblemResponse(503, "overloaded", "Server busy", "every HTTP worker is busy; retry later",
                         "Retry-After: 1\r\n");
  (void)!send(req.sock, r.data(), r.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  Conn lingering;
  lingering.closing = true;
  lingering.deadline = Clock::now() + std::chrono::milliseconds(limits_.linger_ms);
  shutdown(req.sock, SHUT_WR);
  watch(req.sock, std::move(lingering));
}

void HeadReader::dispatchParked() {
  // Any parked head a worker pool takes goes now: a full pool for bodies does not hold back
  // bodiless requests parked behind its requests.
  for (auto it = parked_.begin(); it != parked_.end();)
    it = ready_(*it) ? parked_.erase(it) : it + 1;
  const auto too_old = Clock::now() - std::chrono::milliseconds(limits_.timeout_ms);
  while (!parked_.empty() && parked_.front().accepted < too_old) {
    answerBusy(parked_.front());
    parked_.pop_front();
  }
}

void HeadReader::refuse(int sock, Conn& conn, int status, const char* type, const char* title,
                        const std::string& detail) {
  const std::string r = rawProblemResponse(status, type, title, detail);
  refused_(status);
  (void)!send(sock, r.data(), r.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  shutdown(sock, SHUT_WR);
  conn.closing = true;
  std::string().swap(conn.buf);  // the head's memory goes back now
  conn.deadline = Clock::now() + std::chrono::milliseconds(limits_.linger_ms);
}

void HeadReader::drop(int sock) {
  epoll_ctl(epoll_, EPOLL_CTL_DEL, sock, nullptr);
  close(sock);
  conns_.erase(sock);
}

void HeadReader::expire() {
  const auto now = Clock::now();
  std::vector<int> late;
  for (auto& [sock, conn] : conns_) {
    if (now >= conn.deadline) late.push_back(sock);
  }
  for (int sock : late) {
    Conn& conn = conns_[sock];
    if (conn.closing) {
      drop(sock);
    } else {
      refuse(
          sock, conn, 408, "request-timeout", "Request head too slow",
          "the request head did not arrive within " + std::to_string(limits_.timeout_ms) + " ms");
    }
  }
}

}  // namespace rdm::server
