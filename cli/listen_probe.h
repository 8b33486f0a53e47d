// Why `rdm serve` cannot listen: the daemon's open() says only that it cannot, so the reason
// is found by binding the same address once more, as the daemon does (SO_REUSEADDR).
#pragma once

#include <string>

namespace rdm::cli {

// The operating system's reason binding TCP `address`:`port` fails now, with what to do for
// a port in use or reserved; empty when the bind succeeds.
std::string listenFailureReason(const std::string& address, int port);

}  // namespace rdm::cli
