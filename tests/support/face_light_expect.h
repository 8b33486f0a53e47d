// Two face lights hold the same bits: as the file stores them (RGB9E5), slot by slot; a
// daemon job's face light, downloaded.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "rdm/bake/face_light.h"
#include "rdm/base/file_util.h"
#include "rdm/service/client.h"

namespace rdm::test {

inline void expectSameFaceLight(const FaceLight& want, const FaceLight& got) {
  EXPECT_EQ(got.scene_digest, want.scene_digest);
  EXPECT_EQ(got.spp, want.spp);
  ASSERT_EQ(got.slots.size(), want.slots.size());
  for (size_t i = 0; i < want.slots.size(); ++i) {
    const FaceLightSlot &a = want.slots[i], &b = got.slots[i];
    ASSERT_EQ(b.slot, a.slot);
    ASSERT_EQ(b.faces, a.faces);
    for (size_t f = 0; f < a.light.size(); ++f)
      ASSERT_EQ(encodeRgb9e5(b.light[f]), encodeRgb9e5(a.light[f]))
          << "slot " << i << " face " << f;
  }
}

// A daemon job's face_light.bin, downloaded into `dir` and read back.
inline FaceLight downloadFaceLight(BakeClient& c, const std::string& job, const std::string& dir) {
  auto bytes = c.download(job, "face_light.bin");
  EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.error());
  const std::string path = dir + "/face_light.bin";
  EXPECT_TRUE(writeFileAtomic(path, bytes.ok() ? *bytes : std::string()).ok());
  auto light = readFaceLight(path);
  EXPECT_TRUE(light.ok()) << (light.ok() ? "" : light.error());
  return light.ok() ? *light : FaceLight{};
}

}  // namespace rdm::test
