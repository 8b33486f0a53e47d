// The bake daemon (`rdm serve`): stores, job manager and the hardened HTTP server.
#pragma once

#include <memory>
#include <string>

#include "rdm/base/status.h"
#include "server_config.h"

namespace rdm::server {

class BakeServer {
 public:
  explicit BakeServer(ServerConfig config);
  ~BakeServer();
  BakeServer(const BakeServer&) = delete;
  BakeServer& operator=(const BakeServer&) = delete;

  // Loads the data directory, resumes unfinished jobs and binds the socket.
  Status open();
  int port() const;
  // After open(): where jobs bake, and why (JobManager::backendLine).
  std::string backendLine() const;
  // Serves until stop() (thread-safe, also from a signal-waiting thread).
  Status run();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rdm::server
