// The httplib::Stream a worker serves one request through: first the bytes the head reader
// already received, then the socket, with a per-read timeout, a deadline for the whole
// request, a least average rate for the body and for the response (a client that reads or
// sends slower loses its connection) and an abort flag that server shutdown sets: reads end
// at once, writes within kAbortWriteMs (docs/deploy.md).
#pragma once

#include <atomic>
#include <chrono>
#include <string>

#include <httplib.h>

namespace rdm::server {

// The least average rate of a body or a response: after `grace_ms`, a transfer of B bytes
// may take grace_ms + B / bytes_per_s.
struct RateLimit {
  double bytes_per_s = 256.0 * 1024.0;
  int grace_ms = 5000;
};

class PrefixedSocketStream : public httplib::Stream {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr int kAbortWriteMs = 2000;
  PrefixedSocketStream(int sock, std::string prefix, int read_timeout_ms, int write_timeout_ms,
                       Clock::time_point read_deadline, RateLimit rate,
                       const std::atomic<bool>& aborted);

  bool is_readable() const override;
  bool is_writable() const override;
  ssize_t read(char* ptr, size_t size) override;
  ssize_t write(const char* ptr, size_t size) override;
  void get_remote_ip_and_port(std::string& ip, int& port) const override;
  void get_local_ip_and_port(std::string& ip, int& port) const override;
  socket_t socket() const override { return sock_; }

 private:
  // Waits for `events` in 100 ms slices; false on timeout, deadline, too slow a rate or abort.
  bool waitFor(short events, int timeout_ms, bool reading) const;
  // When the transfer so far (`bytes` since `start`) falls below the least rate.
  Clock::time_point rateDeadline(Clock::time_point start, size_t bytes) const;

  int sock_;
  std::string buf_;
  size_t off_ = 0;
  int read_timeout_ms_, write_timeout_ms_;
  Clock::time_point read_deadline_;
  RateLimit rate_;
  Clock::time_point created_, first_write_{};
  size_t body_read_ = 0, written_ = 0;  // socket bytes, not counting the prefix
  mutable Clock::time_point abort_seen_{};
  const std::atomic<bool>& aborted_;
};

}  // namespace rdm::server
