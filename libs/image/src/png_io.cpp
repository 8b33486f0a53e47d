#include "rdm/image/png_io.h"

#include <stb_image_write.h>

#include "rdm/base/check.h"
#include "rdm/base/file_util.h"

namespace rdm {

Status writePng(const std::string& path, int width, int height, int channels,
                const std::vector<uint8_t>& pixels) {
  RDM_CHECK(channels == 3 || channels == 4);
  RDM_CHECK(width > 0 && height > 0);
  RDM_CHECK(pixels.size() == size_t(width) * height * channels);
  std::string bytes;
  auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
  };
  if (!stbi_write_png_to_func(append, &bytes, width, height, channels, pixels.data(),
                              width * channels))
    return Status::error("cannot encode PNG '" + path + "': stb_image_write failed");
  return writeFileAtomic(path, bytes);
}

}  // namespace rdm
