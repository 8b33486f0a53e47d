// Two face lights hold the same bits: as the file stores them (RGB9E5), slot by slot.
#pragma once

#include <gtest/gtest.h>

#include "rdm/bake/face_light.h"

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

}  // namespace rdm::test
