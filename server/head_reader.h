// Reads the request heads of accepted connections on one epoll thread, so that a slow or idle
// client costs a file descriptor and at most `max_bytes` of buffer, never an HTTP worker
// (docs/deploy.md, "Which layer enforces which limit"). Refuses, with a problem+json response
// written here: heads over `max_bytes` or `max_fields` (431), heads not complete within
// `timeout_ms` (408), methods the API does not know (501) and connections past `max_pending`
// (503). Complete heads wait here, not on a thread, while every worker is busy.
#pragma once

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rdm/base/status.h"

namespace rdm::server {

struct HeadLimits {
  size_t max_bytes = 64u << 10;  // request line + header fields + blank line
  int max_fields = 100;
  int timeout_ms = 10000;     // from accept to the blank line
  size_t max_pending = 4096;  // connections whose head is still arriving
  int linger_ms = 2000;       // how long a refused connection's input is drained
};

// A complete head, handed to a worker. `bytes` holds the head without its Range fields, plus
// whatever part of the body already arrived; `range` is the single Range value, if exactly one.
struct PendingRequest {
  int sock = -1;
  std::string bytes;
  std::optional<std::string> range;
  bool has_body = false;  // a non-zero Content-Length or a Transfer-Encoding
  size_t body_bytes = 0;  // the Content-Length, when one was given
  std::chrono::steady_clock::time_point accepted;
};

class HeadReader {
 public:
  // `ready` must not block; false means no worker can take it now (the head is parked and
  // offered again when a worker finishes, or answered 503 after `timeout_ms`).
  using Ready = std::function<bool(PendingRequest&)>;
  using Refused = std::function<void(int status)>;  // counts each refusal (metrics)
  HeadReader(HeadLimits limits, Ready ready, Refused refused);
  ~HeadReader();
  HeadReader(const HeadReader&) = delete;
  HeadReader& operator=(const HeadReader&) = delete;

  // Fails (the server cannot start) when the kernel refuses an epoll or eventfd descriptor,
  // e.g. past the process's descriptor limit.
  [[nodiscard]] Status start();
  // Takes ownership of an accepted socket.
  void add(int sock);
  // Takes back a socket whose response was written: drains its input, then closes it.
  void linger(int sock);
  // Closes every connection still held and joins the thread.
  void stop();

 private:
  struct Conn {
    std::string buf;
    std::chrono::steady_clock::time_point accepted, deadline;
    bool closing = false;
  };
  void loop();
  void watch(int sock, Conn conn);
  void onReadable(int sock);
  void onHead(int sock, Conn& conn, size_t head_end);
  void refuse(int sock, Conn& conn, int status, const char* type, const char* title,
              const std::string& detail);
  void drop(int sock);
  void expire();
  // Hands parked heads to workers in arrival order while they take them.
  void dispatchParked();
  void answerBusy(PendingRequest& req);

  const HeadLimits limits_;
  Ready ready_;
  Refused refused_;
  int epoll_ = -1, wake_ = -1;
  std::mutex mutex_;
  std::vector<std::pair<int, bool>> incoming_;  // socket, linger
  bool stopping_ = false;
  std::map<int, Conn> conns_;  // owned by the reader thread
  // Complete heads no worker could take yet (HTTP workers busy), oldest first.
  std::deque<PendingRequest> parked_;
  std::thread thread_;
};

// The raw bytes of a complete `Connection: close` problem+json response.
std::string rawProblemResponse(int status, const std::string& type, const std::string& title,
                               const std::string& detail, const std::string& extra_headers = {});

}  // namespace rdm::server
