#include "rdm/image/exr_io.h"

#include <Imath/half.h>
#include <OpenEXR/IexBaseExc.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfName.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <utility>

#include "rdm/base/file_util.h"
#include "rdm/base/parallel.h"

namespace rdm {
namespace {

constexpr char kMemoryName[] = "<memory>";

// OStream over a growing std::string. Records any failure, because ~OutputFile writes the
// line offset table and swallows exceptions.
class StringOStream final : public Imf::OStream {
 public:
  StringOStream() : Imf::OStream(kMemoryName) {}

  void write(const char c[], int n) override {
    try {
      const size_t end = pos_ + size_t(n);
      if (end > bytes_.size()) bytes_.resize(end);
      std::memcpy(bytes_.data() + pos_, c, size_t(n));
      pos_ = end;
    } catch (...) {
      failed_ = true;
      throw;
    }
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = size_t(pos); }

  bool failed() const { return failed_; }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
  size_t pos_ = 0;
  bool failed_ = false;
};

// OStream over a file written in place (it seeks back for the line offset table), so a
// page is never held twice in memory. Consecutive writes (OpenEXR writes the header an
// attribute at a time) are gathered into runs of up to kFileRunBytes before they reach the
// file; flush() writes the last run. Failures are recorded by the writer.
class FileOStream final : public Imf::OStream {
 public:
  static constexpr size_t kFileRunBytes = size_t(1) << 20;

  FileOStream(AtomicFileWriter& file, const std::string& path)
      : Imf::OStream(path.c_str()), file_(file) {}
  void write(const char c[], int n) override {
    if (pos_ != run_at_ + run_.size()) flush();  // after a seek: a new run
    if (run_.empty()) run_at_ = pos_;
    run_.append(c, size_t(n));
    pos_ += uint64_t(n);
    if (run_.size() >= kFileRunBytes) flush();
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = pos; }
  void flush() {
    if (!run_.empty()) file_.writeAt(run_at_, run_.data(), run_.size());
    run_.clear();
  }

 private:
  AtomicFileWriter& file_;
  uint64_t pos_ = 0, run_at_ = 0;  // run_ holds the bytes of [run_at_, run_at_ + size)
  std::string run_;
};

// The pool OpenEXR compresses and decompresses chunks on: its size follows setExrThreads,
// made once before the first file unless set. Guarded by the mutex: OpenEXR's pool must not
// be resized concurrently.
std::mutex exr_threads_mutex;
int exr_threads = -1;  // workers of OpenEXR's pool; -1: not set yet

// Under ThreadSanitizer OpenEXR stays on the calling thread: its pool (IlmThread, not
// instrumented) synchronises in ways TSan cannot see, and reports races on the chunk buffers
// it hands between threads, as oneTBB does (docs/dependencies.md). The bytes do not depend on
// the count (ExrIoTest.BytesDoNotDependOnCompressionThreads, in the other passes).
#if defined(__SANITIZE_THREAD__)
constexpr bool kPoolAllowed = false;
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
constexpr bool kPoolAllowed = false;
#else
constexpr bool kPoolAllowed = true;
#endif
#else
constexpr bool kPoolAllowed = true;
#endif

void resizeExrPool(int threads) {
  if (!kPoolAllowed) threads = 1;
  // OpenEXR runs a pool of one thread serially through that thread: 0 runs tasks inline.
  const int pool = threads > 1 ? threads : 0;
  if (Imf::globalThreadCount() != pool) Imf::setGlobalThreadCount(pool);
  exr_threads = threads;
}

// The file's thread count, after making the pool on first use.
int exrThreadCount() {
  std::lock_guard<std::mutex> lock(exr_threads_mutex);
  if (exr_threads < 0) resizeExrPool(workerCount(0));
  return exr_threads > 1 ? exr_threads : 0;
}

// IStream over bytes that outlive it; throws on reads past the end.
class StringIStream final : public Imf::IStream {
 public:
  explicit StringIStream(const std::string& bytes) : Imf::IStream(kMemoryName), bytes_(bytes) {}

  bool read(char c[], int n) override {
    if (n < 0 || pos_ > bytes_.size() || size_t(n) > bytes_.size() - pos_) {
      throw Iex::InputExc("unexpected end of EXR data");
    }
    std::memcpy(c, bytes_.data() + pos_, size_t(n));
    pos_ += uint64_t(n);
    return pos_ < bytes_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }

 private:
  const std::string& bytes_;
  uint64_t pos_ = 0;
};

Status checkNames(const std::vector<std::string>& names) {
  if (names.empty()) return Status::error("no channel names given");
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty()) return Status::error("channel name " + std::to_string(i) + " is empty");
    if (names[i].size() > size_t(Imf::Name::MAX_LENGTH)) {
      return Status::error("channel name '" + names[i].substr(0, 32) + "...' is too long");
    }
    for (size_t j = 0; j < i; ++j) {
      if (names[i] == names[j]) return Status::error("channel '" + names[i] + "' is listed twice");
    }
  }
  return Status();
}

Status checkSize(long long width, long long height) {
  if (width < 1 || height < 1 || width * height > kMaxExrPixels) {
    return Status::error("image size " + std::to_string(width) + " x " + std::to_string(height) +
                         ": width and height must be at least 1 and width * height at most " +
                         std::to_string(kMaxExrPixels));
  }
  return Status();
}

Status checkImage(const Image& image, const std::vector<std::string>& names) {
  if (Status status = checkNames(names); !status.ok()) return status;
  if (size_t(image.channels) != names.size()) {
    return Status::error("image has " + std::to_string(image.channels) + " channels but " +
                         std::to_string(names.size()) + " channel names were given");
  }
  if (Status status = checkSize(image.width, image.height); !status.ok()) return status;
  if (image.pixels.size() != size_t(image.width) * size_t(image.height) * names.size()) {
    return Status::error("image pixel buffer holds " + std::to_string(image.pixels.size()) +
                         " floats, not width * height * channels");
  }
  return Status();
}

Status withContext(const char* function, const std::string& where, const Status& status) {
  return Status::error(status.code(), std::string(function) + " " + where + ": " + status.message(),
                       status.field());
}

// Interleaved float slices of `image`, channel c named names[c].
Imf::FrameBuffer frameBufferFor(const Image& image, const std::vector<std::string>& names) {
  const size_t x_stride = sizeof(float) * size_t(image.channels);
  const size_t y_stride = x_stride * size_t(image.width);
  Imf::FrameBuffer frame_buffer;
  for (size_t c = 0; c < names.size(); ++c) {
    // OpenEXR only reads through the pointer when writing a file.
    char* base = reinterpret_cast<char*>(const_cast<float*>(image.pixels.data() + c));
    frame_buffer.insert(names[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
  }
  return frame_buffer;
}

bool isHalf(const std::vector<std::string>& half, const std::string& name) {
  return std::find(half.begin(), half.end(), name) != half.end();
}

// Writes the whole file to `stream`; throws on failure. Expects checkImage to pass. OpenEXR
// does not convert on write, so HALF channels go through a converted copy.
void encodeTo(Imf::OStream& stream, const Image& image, const std::vector<std::string>& names,
              const std::vector<std::string>& half) {
  // Header(w, h) has exactly the required attributes, with both windows (0,0)-(W-1,H-1).
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.lineOrder() = Imf::INCREASING_Y;
  for (const std::string& name : names)
    header.channels().insert(name, Imf::Channel(isHalf(half, name) ? Imf::HALF : Imf::FLOAT));
  Imf::FrameBuffer frame_buffer = frameBufferFor(image, names);
  const size_t texels = size_t(image.width) * size_t(image.height);
  std::vector<std::vector<Imath::half>> converted;
  for (size_t c = 0; c < names.size(); ++c) {
    if (!isHalf(half, names[c])) continue;
    std::vector<Imath::half>& plane = converted.emplace_back(texels);
    for (size_t i = 0; i < texels; ++i) plane[i] = Imath::half(image.pixels[i * names.size() + c]);
    frame_buffer.insert(
        names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(plane.data()), sizeof(Imath::half),
                             sizeof(Imath::half) * size_t(image.width)));
  }
  Imf::OutputFile file(stream, header, exrThreadCount());
  file.setFrameBuffer(frame_buffer);
  file.writePixels(image.height);
}

std::string channelListText(const Imf::ChannelList& channels) {
  std::string text;
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    text += (text.empty() ? "" : ", ") + std::string(it.name());
  }
  return text.empty() ? "none" : text;
}

Status checkChannels(const Imf::ChannelList& channels, const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    const Imf::Channel* channel = channels.findChannel(name);
    if (channel == nullptr) {
      return Status::error("no channel '" + name + "' (file has " + channelListText(channels) +
                           ")");
    }
    if (channel->xSampling != 1 || channel->ySampling != 1) {
      return Status::error("channel '" + name + "' is subsampled");
    }
  }
  return Status();
}

// Reads `names` from an open file; throws on OpenEXR failures.
Expected<Image> decodeFrom(Imf::InputFile& file, const std::vector<std::string>& names) {
  const Imath::Box2i& window = file.header().dataWindow();
  if (window.min.x != 0 || window.min.y != 0) {
    return Status::error("data window starts at (" + std::to_string(window.min.x) + "," +
                         std::to_string(window.min.y) + "), not (0,0)");
  }
  const long long width = (long long)window.max.x + 1;
  const long long height = (long long)window.max.y + 1;
  if (Status status = checkSize(width, height); !status.ok()) return status;
  if (Status status = checkChannels(file.header().channels(), names); !status.ok()) return status;
  Image image(int(width), int(height), int(names.size()));
  file.setFrameBuffer(frameBufferFor(image, names));
  file.readPixels(0, int(height) - 1);
  return image;
}

// Reads `names` from `stream`, or from the file at `where` when `stream` is null.
Expected<Image> decodeWithContext(const char* function, const std::string& where,
                                  Imf::IStream* stream, const std::vector<std::string>& names) {
  if (Status status = checkNames(names); !status.ok()) return withContext(function, where, status);
  try {
    const int threads = exrThreadCount();
    std::unique_ptr<Imf::InputFile> file =
        stream != nullptr ? std::make_unique<Imf::InputFile>(*stream, threads)
                          : std::make_unique<Imf::InputFile>(where.c_str(), threads);
    Expected<Image> image = decodeFrom(*file, names);
    if (!image.ok()) return withContext(function, where, image.status());
    return image;
  } catch (const std::exception& e) {
    return withContext(function, where, Status::error(e.what()));
  }
}

// The file's bytes, or why they cannot be made (without context: the callers add theirs).
Expected<std::string> encodeBytes(const Image& image, const std::vector<std::string>& names,
                                  const std::vector<std::string>& half = {}) {
  if (Status status = checkImage(image, names); !status.ok()) return status;
  StringOStream stream;
  try {
    encodeTo(stream, image, names, half);
  } catch (const std::exception& e) {
    return Status::error(e.what());
  }
  if (stream.failed()) return Status::error("writing to memory failed");
  return stream.take();
}

}  // namespace

void setExrThreads(int threads) {
  std::lock_guard<std::mutex> lock(exr_threads_mutex);
  resizeExrPool(workerCount(threads));
}

Status writeExr(const std::string& path, const Image& image,
                const std::vector<std::string>& channel_names,
                const std::vector<std::string>& half_channels) {
  if (Status status = checkImage(image, channel_names); !status.ok())
    return withContext("writeExr", path, status);
  auto file = AtomicFileWriter::create(path);
  if (!file) return withContext("writeExr", path, file.status());
  try {
    FileOStream stream(**file, path);
    encodeTo(stream, image, channel_names, half_channels);
    stream.flush();
  } catch (const std::exception& e) {
    return withContext("writeExr", path, Status::error(e.what()));
  }
  if (Status status = (*file)->commit(); !status.ok()) return withContext("writeExr", path, status);
  return Status();
}

Expected<std::string> encodeExr(const Image& image, const std::vector<std::string>& channel_names) {
  auto bytes = encodeBytes(image, channel_names);
  if (!bytes) return withContext("encodeExr", kMemoryName, bytes.status());
  return bytes;
}

Expected<Image> readExr(const std::string& path, const std::vector<std::string>& channel_names) {
  return decodeWithContext("readExr", path, nullptr, channel_names);
}

Expected<Image> readFiniteExr(const std::string& path,
                              const std::vector<std::string>& channel_names) {
  Expected<Image> image = readExr(path, channel_names);
  if (!image) return image;
  const size_t channels = channel_names.size();
  for (size_t i = 0; i < image->pixels.size(); ++i) {
    if (std::isfinite(image->pixels[i])) continue;
    const size_t pixel = i / channels;
    return Status::invalid("", path + ": non-finite value in channel " +
                                   channel_names[i % channels] + " at pixel (" +
                                   std::to_string(pixel % size_t(image->width)) + ", " +
                                   std::to_string(pixel / size_t(image->width)) + ")");
  }
  return image;
}

Expected<Image> decodeExr(const std::string& bytes, const std::vector<std::string>& channel_names) {
  StringIStream stream(bytes);
  return decodeWithContext("decodeExr", kMemoryName, &stream, channel_names);
}

}  // namespace rdm
