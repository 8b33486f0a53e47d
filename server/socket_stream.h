// The httplib::Stream a worker serves one request through: first the bytes the head reader
// already received, then the socket, with a per-read timeout, a deadline for the whole
// request and an abort flag that server shutdown sets (docs/deploy.md).
#pragma once

#include <atomic>
#include <chrono>
#include <string>

#include <httplib.h>

namespace rdm::server {

class PrefixedSocketStream : public httplib::Stream {
 public:
  using Clock = std::chrono::steady_clock;
  PrefixedSocketStream(int sock, std::string prefix, int read_timeout_ms, int write_timeout_ms,
                       Clock::time_point read_deadline, const std::atomic<bool>& aborted);

  bool is_readable() const override;
  bool is_writable() const override;
  ssize_t read(char* ptr, size_t size) override;
  ssize_t write(const char* ptr, size_t size) override;
  void get_remote_ip_and_port(std::string& ip, int& port) const override;
  void get_local_ip_and_port(std::string& ip, int& port) const override;
  socket_t socket() const override { return sock_; }

 private:
  // Waits for `events` in 100 ms slices; false on timeout, deadline or abort.
  bool waitFor(short events, int timeout_ms, bool reading) const;

  int sock_;
  std::string buf_;
  size_t off_ = 0;
  int read_timeout_ms_, write_timeout_ms_;
  Clock::time_point read_deadline_;
  const std::atomic<bool>& aborted_;
};

}  // namespace rdm::server
