// What several daemon tests ask of a job: the chess scene at given settings, a problem reply's
// shape (docs/spec.md section 8.1), a job's atlas downloaded and read back.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "rdm/atlas/atlas.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"

namespace rdm::test {

// Chess at the given RDM settings, without the face light unless a test asks for it.
inline std::string chessJson(int spp, int hemisphere, int face_light_spp = 0) {
  Scene s = *builtinScene("chess");
  s.bake.spp = spp, s.bake.max_hemisphere = hemisphere;
  s.face_light_spp = face_light_spp;
  return sceneToJson(s);
}

// An application/problem+json reply with `status`, naming `field` when one is given.
inline void expectProblem(const Expected<HttpReply>& r, int status, const std::string& field = {}) {
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->header("Content-Type"), "application/problem+json") << r->body;
  const nlohmann::json j = nlohmann::json::parse(r->body, nullptr, false);
  ASSERT_TRUE(j.is_object()) << r->body;
  EXPECT_EQ(j.value("status", 0), status);
  EXPECT_TRUE(j.contains("type") && j.contains("title") && j.contains("detail")) << r->body;
  if (!field.empty()) {
    EXPECT_EQ(j.value("field", ""), field) << r->body;
  }
}

// A job's index.json and atlas page 0, downloaded into `dir` and read back.
inline LoadedAtlas downloadAtlas(BakeClient& c, const std::string& job, const std::string& dir) {
  for (const std::string& name : {std::string("index.json"), atlasPageFileName(0)}) {
    auto bytes = c.download(job, name);
    EXPECT_TRUE(bytes.ok()) << name << ": " << (bytes.ok() ? "" : bytes.error());
    if (bytes.ok()) {
      EXPECT_TRUE(writeFileAtomic(dir + "/" + name, *bytes).ok());
    }
  }
  auto atlas = readAtlasOutputs(dir);
  EXPECT_TRUE(atlas.ok()) << (atlas.ok() ? "" : atlas.error());
  return atlas.ok() ? *atlas : LoadedAtlas{};
}

}  // namespace rdm::test
