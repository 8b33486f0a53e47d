// Ctrl-C during `rdm bake`: the first SIGINT asks the bake to stop between work units (RDM
// units, face light slots and faces) and to write nothing; a second ends the process at once.
#pragma once

#include <atomic>

namespace rdm::cli {

// The flag the first SIGINT sets; the bake's phases poll it as their cancel / stop flag.
const std::atomic<bool>* interruptFlag();
bool interrupted();

// From now on the first SIGINT sets the flag and the next one ends the process.
void stopOnInterrupt();
// From now on every SIGINT only sets the flag: for the short, atomic writes of finished results.
void recordInterrupt();

// Prints, once and only after a SIGINT, that the bake is stopping without writing.
void announceInterrupt(const char* verb);

}  // namespace rdm::cli
