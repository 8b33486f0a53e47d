// Stored data that proves itself (docs/spec.md section 8.10, "Checksums"): a job's result
// manifest, a scene's version files and its meta.json. Each case damages a file the way a
// disk or a crash does (a flipped bit, a truncation) and expects the damage to be named,
// never read as data.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "fresh_dir.h"
#include "rdm/atlas/rdm_store.h"
#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"
#include "rdm/scene/scene.h"
#include "rdm/service/scene_store.h"
#include "rdm/service/stored_file.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("stored", name);
}

void put(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

std::string get(const std::string& path) {
  auto bytes = readFileToString(path);
  return bytes ? *bytes : std::string();
}

// The code of a result, kOk when it holds a value (status() of a value is a bug).
template <class T>
StatusCode codeOf(const Expected<T>& e) {
  return e.ok() ? StatusCode::kOk : e.status().code();
}

void flipBit(const std::string& path, size_t at, int bit = 2) {
  std::string bytes = get(path);
  ASSERT_LT(at, bytes.size());
  bytes[at] = char(bytes[at] ^ (1 << bit));
  put(path, bytes);
}

TEST(StoredFile, ManifestListsResultFilesAndChecksThemOnRead) {
  const std::string dir = freshDir("manifest");
  put(dir + "/atlas.exr", std::string(5000, 'a') + "tail");
  put(dir + "/index.json", "{\"entries\": []}\n");
  put(dir + "/" + kRdmStoreFile, "checks itself");
  put(dir + "/index.json.tmp.12.3", "a writer's temporary");
  ASSERT_TRUE(writeResultChecksums(dir).ok());
  auto manifest = readResultChecksums(dir);
  ASSERT_TRUE(manifest.ok()) << manifest.error();
  EXPECT_EQ(manifest->size(), 2u);
  EXPECT_EQ(manifest->at("atlas.exr"), contentHash(get(dir + "/atlas.exr")));

  auto intact = readVerifiedResult(dir, "index.json");
  ASSERT_TRUE(intact.ok()) << intact.error();
  EXPECT_TRUE(intact->verified);
  EXPECT_EQ(intact->hash, contentHash(intact->bytes));

  flipBit(dir + "/atlas.exr", 4100);
  auto flipped = readVerifiedResult(dir, "atlas.exr");
  ASSERT_FALSE(flipped.ok());
  EXPECT_EQ(flipped.status().code(), StatusCode::kCorrupt);
  EXPECT_NE(flipped.error().find("checksum"), std::string::npos) << flipped.error();
  EXPECT_FALSE(fs::exists(dir + "/atlas.exr"));  // quarantined
  EXPECT_TRUE(fs::exists(dir + "/atlas.exr.corrupt"));
  auto again = readVerifiedResult(dir, "atlas.exr");  // stays an answer of damage, not 404
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.status().code(), StatusCode::kCorrupt);

  put(dir + "/index.json", get(dir + "/index.json").substr(0, 7));  // torn
  auto torn = readVerifiedResult(dir, "index.json");
  ASSERT_FALSE(torn.ok());
  EXPECT_EQ(torn.status().code(), StatusCode::kCorrupt);
}

TEST(StoredFile, DamagedManifestIsToldApartAndOldJobsReadUnverified) {
  const std::string dir = freshDir("manifest_damage");
  put(dir + "/index.txt", "text");
  auto unverified = readVerifiedResult(dir, "index.txt");  // no manifest: a job from before
  ASSERT_TRUE(unverified.ok()) << unverified.error();
  EXPECT_FALSE(unverified->verified);
  EXPECT_EQ(codeOf(readVerifiedResult(dir, "nothing.bin")), StatusCode::kNotFound);
  ASSERT_TRUE(writeResultChecksums(dir).ok());
  const std::string manifest = dir + "/" + kChecksumsFile;
  const std::string text = get(manifest);
  const size_t digit = text.find("\"index.txt\"") + 14;  // inside its hash
  flipBit(manifest, digit, 0);
  EXPECT_EQ(codeOf(readResultChecksums(dir)), StatusCode::kCorrupt);
  auto read = readVerifiedResult(dir, "index.txt");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kCorrupt);
  EXPECT_TRUE(fs::exists(dir + "/index.txt"));  // an intact file is not moved for it
  put(manifest, text.substr(0, text.size() / 2));
  EXPECT_EQ(codeOf(readResultChecksums(dir)), StatusCode::kCorrupt);
}

Scene smallScene() {
  Scene s = *builtinScene("chess");
  s.bake.spp = 1;
  return s;
}

// A scene at versions 1 and 2 in a fresh store under `dir`.
std::string twoVersions(const std::string& dir) {
  SceneStore store(dir, 8);
  EXPECT_TRUE(store.load().ok());
  auto created = store.create(smallScene());
  EXPECT_TRUE(created.ok());
  auto patched = store.patch(created->id, json{{"base_version", 1}, {"emission_scale", 1.5}},
                             [](const Scene&) { return Status(); });
  EXPECT_TRUE(patched.ok()) << patched.error();
  return created->id;
}

TEST(StoredFile, TornOrFlippedSceneVersionFailsThatVersionOnly) {
  const std::string dir = freshDir("scene_versions");
  const std::string id = twoVersions(dir);
  const std::string v1 = dir + "/scenes/" + id + "/v1.json",
                    v2 = dir + "/scenes/" + id + "/v2.json";
  EXPECT_TRUE(fs::exists(v1 + ".xxh3"));
  const std::string v2_bytes = get(v2);
  put(v2, v2_bytes.substr(0, v2_bytes.size() / 2));  // torn
  {
    SceneStore store(dir, 8);
    ASSERT_TRUE(store.load().ok());
    ASSERT_EQ(store.list().size(), 1u);
    EXPECT_EQ(store.info(id)->version, 2);
    EXPECT_TRUE(store.find(id, 1).ok());
    auto torn = store.find(id, 2);
    ASSERT_FALSE(torn.ok());
    EXPECT_EQ(torn.status().code(), StatusCode::kCorrupt);
    EXPECT_NE(torn.error().find("version 2"), std::string::npos) << torn.error();
  }
  // A flipped bit inside a number still parses as a scene: only the checksum tells.
  const std::string v1_bytes = get(v1);
  const size_t digit = v1_bytes.find_first_of("123456789", v1_bytes.size() / 2);
  ASSERT_NE(digit, std::string::npos);
  flipBit(v1, digit, 0);
  SceneStore store(dir, 8);
  ASSERT_TRUE(store.load().ok());
  auto flipped = store.find(id, 1);
  ASSERT_FALSE(flipped.ok());
  EXPECT_EQ(flipped.status().code(), StatusCode::kCorrupt);
}

TEST(StoredFile, TornOrFlippedMetaIsRebuiltFromTheVersionFiles) {
  for (const bool torn : {true, false}) {
    const std::string dir = freshDir(torn ? "meta_torn" : "meta_flipped");
    const std::string id = twoVersions(dir);
    const std::string meta = dir + "/scenes/" + id + "/meta.json";
    if (torn) {
      put(meta, get(meta).substr(0, 10));
    } else {  // "version":2 -> "version":3: valid JSON, a wrong record
      std::string text = get(meta);
      const size_t at = text.find("\"version\":2");
      ASSERT_NE(at, std::string::npos) << text;
      text[at + 10] = '3';
      put(meta, text);
    }
    {
      SceneStore store(dir, 8);
      ASSERT_TRUE(store.load().ok());
      ASSERT_TRUE(store.info(id).has_value()) << "the scene's intact versions stay";
      EXPECT_EQ(store.info(id)->version, 2);
      EXPECT_TRUE(store.find(id, 1).ok());
      EXPECT_TRUE(store.find(id, 2).ok());
    }
    SceneStore again(dir, 8);  // meta.json was written again
    ASSERT_TRUE(again.load().ok());
    EXPECT_EQ(again.info(id)->version, 2);
    EXPECT_NE(get(meta).find("\"check\""), std::string::npos);
  }
}

}  // namespace
}  // namespace rdm
