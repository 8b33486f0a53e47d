// Resource ids: a one-letter kind prefix and 16 random hex digits ("s3f9a...", "j07c1...").
// Ids are validated before they reach the file system.
#pragma once

#include <string>

namespace rdm {

std::string newId(char kind);
bool validId(const std::string& id, char kind);

}  // namespace rdm
