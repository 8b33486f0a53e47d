// The one content hash: XXH3 64 (libxxhash) of bytes, for the unit log's checksums, the
// shard manifests' scene digests and the daemon's body ETags (docs/spec.md 8.2, 8.10).
// Not cryptographic: it detects torn files and changed content, not tampering.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace rdm {

uint64_t contentHash(std::string_view bytes);
// contentHash as 16 lower-case hex digits.
std::string contentHashHex(std::string_view bytes);

}  // namespace rdm
