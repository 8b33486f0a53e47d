// RFC 4648 standard-alphabet base64, padded, no line breaks.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rdm/base/status.h"

namespace rdm {

std::string base64Encode(const std::vector<uint8_t>& bytes);
// Errors name the offset of the first bad character or a wrong length.
Expected<std::vector<uint8_t>> base64Decode(const std::string& text);

}  // namespace rdm
