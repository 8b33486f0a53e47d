// What this machine can hold, read when asked: the limits a bake or a daemon job is held to
// before it starts (docs/api.md, "Admission"; `rdm bake` prints its estimate against them).
#pragma once

#include <cstdint>
#include <string>

namespace rdm {

uint64_t physicalMemoryBytes();
// MemAvailable of /proc/meminfo (what can be allocated without swapping), or the physical
// memory where the kernel does not say.
uint64_t availableMemoryBytes();
// Bytes an unprivileged writer may still put on the filesystem holding `path`; 0 when it
// cannot be read.
uint64_t freeDiskBytes(const std::string& path);
// "1.23 GB", "456 MB", "789 kB": decimal units, three significant digits.
std::string formatBytes(uint64_t bytes);

}  // namespace rdm
