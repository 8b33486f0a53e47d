// OpenEXR IO for rdm::Image (docs/spec.md section 4). Every file written here is single-part
// scanline, channels 32-bit FLOAT unless named as HALF, ZIP compression, data window = display
// window = (0,0)-(W-1,H-1), INCREASING_Y, and carries only the attributes OpenEXR requires. The
// file's first scanline is image row 0 (top); nothing flips rows.
//
// Channel order: OpenEXR stores channels sorted by name; an Image's interleaved channel c
// is always channel_names[c], whatever the order in the file.
//
// All functions catch OpenEXR (Iex) and allocation exceptions and return them as Status
// errors that name the file (or "<memory>") and, where there is one, the channel.
//
// Threads: OpenEXR compresses (and decompresses) a file's chunks, 16 rows each for ZIP, on
// its process-wide pool; each chunk is compressed on its own and they are written in order,
// so the bytes do not depend on the thread count (tests ExrIoTest.*Threads*).
#pragma once

#include <string>
#include <vector>

#include "rdm/base/status.h"
#include "rdm/image/image.h"

namespace rdm {

// Workers of OpenEXR's pool for every file read and written after the call, process-wide
// (rdm::workerCount: 0 is one per hardware thread, the default; 1 compresses on the calling
// thread). A program calls it once, from its --threads option, before it writes files; not
// from a thread of OpenEXR's own pool.
void setExrThreads(int threads);

// Largest image these functions accept: one 16384 x 16384 atlas page (docs/spec.md section 4).
// Protects readers from headers that claim absurd sizes.
inline constexpr long long kMaxExrPixels = 16384LL * 16384LL;

// The channel sets of docs/spec.md section 4: RDM maps, atlas pages and their deltas carry
// radiance and depth; renders and other colour images radiance only.
inline const std::vector<std::string> kRgbzChannels = {"R", "G", "B", "Z"};
inline const std::vector<std::string> kRgbChannels = {"R", "G", "B"};

// Writes `image` to `path` atomically: the bytes go to `path + ".tmp"` in the same
// directory, are flushed to disk, and are renamed over `path`. On failure the temp file is
// removed, `path` is untouched, and the error names `path`. Requires
// channel_names.size() == image.channels, unique non-empty names, width and height >= 1,
// width * height <= kMaxExrPixels and pixels.size() == width * height * channels.
// Channels in `half_channels` are stored as 16-bit HALF, rounded to nearest; the caller keeps
// their values within +-65504.
Status writeExr(const std::string& path, const Image& image,
                const std::vector<std::string>& channel_names,
                const std::vector<std::string>& half_channels = {});

// The exact bytes writeExr would put in the file, for HTTP responses.
Expected<std::string> encodeExr(const Image& image, const std::vector<std::string>& channel_names);

// Reads the named channels (any pixel type, converted to float) into an Image whose
// channel c is channel_names[c]. Fails, naming the channel and file, when a channel is
// missing or subsampled, when the data window does not start at (0,0), and when it holds
// more than kMaxExrPixels pixels (before allocating them).
Expected<Image> readExr(const std::string& path, const std::vector<std::string>& channel_names);

// readExr, refusing an image with a NaN or an infinity: the error names the channel and the
// pixel (x, y) of the first one. For images that feed a metric (FLIP, means of renders).
Expected<Image> readFiniteExr(const std::string& path,
                              const std::vector<std::string>& channel_names);

// readExr from the bytes of a file held in memory.
Expected<Image> decodeExr(const std::string& bytes, const std::vector<std::string>& channel_names);

}  // namespace rdm
