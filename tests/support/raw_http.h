// Raw HTTP/1.1 over loopback sockets, for tests that need what a client library hides: a
// head or body sent byte by byte, a response never read, the exact bytes of a reply.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>

namespace rdm::test {

inline double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// `receive_buffer` > 0: SO_RCVBUF before connecting, so a client that reads nothing stalls
// the server's writes after few bytes.
inline int openConnection(int port, int receive_buffer = 0) {
  int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer > 0)
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return close(fd), -1;
  return fd;
}

// Reads until the peer closes or `timeout_s` passes.
inline std::string readAll(int fd, double timeout_s) {
  std::string reply;
  const auto start = std::chrono::steady_clock::now();
  char buf[16384];
  while (secondsSince(start) < timeout_s) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    reply.append(buf, size_t(n));
  }
  return reply;
}

// One request on a fresh connection; the whole response (status line, headers, body).
inline std::string rawExchange(int port, const std::string& bytes, double timeout_s = 10) {
  const int fd = openConnection(port);
  if (fd < 0) return {};
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;  // the server may refuse and close early; its answer is still readable
    sent += size_t(n);
  }
  std::string reply = readAll(fd, timeout_s);
  close(fd);
  return reply;
}

inline int statusOf(const std::string& reply) {
  return reply.rfind("HTTP/1.1 ", 0) == 0 ? std::atoi(reply.c_str() + 9) : -1;
}

inline std::string headerOf(const std::string& reply, const std::string& name) {
  std::string lower = reply.substr(0, reply.find("\r\n\r\n"));
  for (char& c : lower) c = char(std::tolower(uint8_t(c)));
  std::string key = "\r\n" + name + ": ";
  for (char& c : key) c = char(std::tolower(uint8_t(c)));
  const size_t at = lower.find(key);
  if (at == std::string::npos) return {};
  const size_t start = at + key.size();
  return reply.substr(start, reply.find("\r\n", start) - start);
}

inline std::string bodyOf(const std::string& reply) {
  const size_t at = reply.find("\r\n\r\n");
  return at == std::string::npos ? std::string() : reply.substr(at + 4);
}

inline std::string post(const std::string& path, const std::string& body,
                        const std::string& extra = {}) {
  return "POST " + path + " HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" + extra +
         "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
}

}  // namespace rdm::test
