// Scene file v1 (docs/spec.md section 2): the loader refuses every malformed input with a message
// naming the field path or byte offset; built-in scenes round-trip and have the shape docs/spec.md
// section 7 asks for; files are written atomically; sRGB decoding matches the known answers.
#include "rdm/scene/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/base/base64.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/world.h"
#include "scene_fixtures.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace rdm::test;

TEST(SceneJsonTest, BaseSceneParses) {
  auto scene = parseSceneJson(baseSceneJson().dump());
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->size, (std::array<int, 3>{4, 3, 4}));
  ASSERT_EQ(scene->palette.size(), 2u);
  EXPECT_EQ(scene->palette[0], (PaletteEntry{{200, 60, 40}, 0, 3, 0}));
  EXPECT_EQ(scene->palette[1], (PaletteEntry{{10, 20, 30}, 7, 0, 2}));  // defaults 7 / 0
  EXPECT_EQ(scene->blocks.at("stone").voxels, std::vector<uint8_t>(4096, 1));
  EXPECT_EQ(scene->blocks.at("ball").voxels, ballVoxels());
  ASSERT_EQ(scene->placements.size(), 3u);
  EXPECT_EQ(scene->placements[1], (Placement{{1, 0, 0}, "ball", 5}));
  EXPECT_EQ(scene->placements[2].rot, 0);  // default
  ASSERT_TRUE(scene->sun.has_value());
  EXPECT_EQ(scene->sun->direction, glm::dvec3(0.3, 1.0, 0.2));
  EXPECT_EQ(scene->sky.ground, glm::dvec3(0.2, 0.18, 0.15));
  EXPECT_EQ(scene->emission_scale, 8.0);
  EXPECT_EQ(scene->bake, (BakeSettings{256, 4, 1, 256}));
  ASSERT_EQ(scene->cameras.size(), 1u);
  EXPECT_EQ(scene->cameras[0].fov_deg, 50.0);
}

TEST(SceneJsonTest, MinimalSceneTakesDefaults) {
  auto scene = parseSceneJson(R"({"format": "rdm-scene", "version": 1, "size": [1, 1, 1]})");
  ASSERT_TRUE(scene.ok()) << scene.error();
  Scene expected;
  expected.size = {1, 1, 1};
  EXPECT_EQ(*scene, expected);
  EXPECT_FALSE(scene->sun.has_value());
  EXPECT_EQ(scene->emission_scale, 1.0);
  EXPECT_EQ(scene->ambient, glm::dvec3(0.0));
  EXPECT_EQ(scene->bake, (BakeSettings{256, 4, 1, 256}));
  EXPECT_EQ(scene->face_light_spp, 0);  // no face light unless the scene asks for one
  EXPECT_TRUE(scene->cameras.empty());

  json j = baseSceneJson();
  j["sun"] = nullptr;  // null = no sun
  auto no_sun = parseSceneJson(j.dump());
  ASSERT_TRUE(no_sun.ok()) << no_sun.error();
  EXPECT_FALSE(no_sun->sun.has_value());
  j["sun"] = {{"direction", {0, 1, 0.5}}};
  auto sun_defaults = parseSceneJson(j.dump());
  ASSERT_TRUE(sun_defaults.ok()) << sun_defaults.error();
  EXPECT_EQ(sun_defaults->sun->angular_radius_deg, 0.27);
  EXPECT_EQ(sun_defaults->sun->irradiance, glm::dvec3(0.0));
}

TEST(SceneJsonTest, AcceptsRangeBoundaries) {
  json j = baseSceneJson();
  j["size"] = {256, 1, 256};
  j["bake"] = {{"spp", 65536}, {"max_bounces", 64}, {"seed", 4294967295LL}, {"max_hemisphere", 2}};
  j["palette"][0] = {{"color", {255, 0, 255}}, {"roughness", 7}, {"metallic", 3}, {"emission", 3}};
  j["sun"]["angular_radius_deg"] = 10;
  j["sun"]["irradiance"] = {1e5, 0, 0};
  j["cameras"][0]["fov_deg"] = 179.9;
  j["emission_scale"] = 1e5;
  j["placements"][2]["rot"] = 23;
  j["placements"][2]["at"] = {255, 0, 255};
  auto scene = parseSceneJson(j.dump());
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->bake.seed, 4294967295u);
  EXPECT_EQ(scene->bake.spp, 65536);
  j["bake"]["seed"] = 0;
  j["bake"]["spp"] = 1;
  j["bake"]["max_bounces"] = 0;
  j["bake"]["max_hemisphere"] = 256;
  j["sun"]["angular_radius_deg"] = 0.01;
  j["cameras"][0]["target"] = {-2.0, -100.0, -1.999};  // steep but not vertical
  EXPECT_TRUE(parseSceneJson(j.dump()).ok());
}

TEST(SceneJsonTest, BadJsonNamesByte) {
  EXPECT_TRUE(refused("", {"byte"}));
  EXPECT_TRUE(refused("{", {"byte"}));
  EXPECT_TRUE(refused(R"({"format": "rdm-scene", "version": 1,, "size": [1, 1, 1]})", {"byte 37"}));
  EXPECT_TRUE(refused(R"({"format": "rdm-scene" "version": 1})", {"byte"}));
  EXPECT_TRUE(refused(R"({"format": 'rdm-scene'})", {"byte 11"}));
  EXPECT_TRUE(refused("{\"format\": \"rdm-\xff\"}", {"byte"}));  // invalid UTF-8
  std::string text = baseSceneJson().dump();
  EXPECT_TRUE(refused(text.substr(0, text.size() / 2), {"byte"}));  // truncated
  EXPECT_TRUE(refused(text + "}", {"byte"}));                       // trailing garbage
}

// Loader bug found by fuzz/scene_fuzzer: a number that overflows a double makes nlohmann::json
// throw out_of_range (406) from json::parse, and parseSceneJson catches only parse_error, so
// the exception escapes (std::terminate in the CLI). Enable once libs/scene/src/scene_json.cpp
// also catches json::exception.
TEST(SceneJsonTest, NumberOverflowIsRefusedNotThrown) {
  for (const std::string text :
       {"1e400", "-1e400", R"({"format": "rdm-scene", "version": 1, "size": [1, 1, 1],
                             "emission_scale": 1e400})"}) {
    SCOPED_TRACE(text);
    try {
      auto scene = parseSceneJson(text);
      ASSERT_FALSE(scene.ok());
      EXPECT_NE(scene.error().find("1e400"), std::string::npos) << scene.error();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "parseSceneJson threw: " << e.what();
    }
  }
}

// Validation gap: target - position = (1e-200, 1, 0) is not exactly vertical, so it is
// accepted, but the camera basis of docs/spec.md section 4 (normalize(forward x up), as render.cpp
// computes it in double) is NaN. Enable once the loader refuses numerically vertical cameras.
TEST(SceneJsonTest, AcceptedCameraHasFiniteBasis) {
  for (double dx : {1e-200, 5e-324, 1e-160}) {
    json j = baseSceneJson();
    j["cameras"][0]["position"] = {0.0, 0.0, 0.0};
    j["cameras"][0]["target"] = {dx, 1.0, 0.0};
    auto scene = parseSceneJson(j.dump());
    if (!scene.ok()) continue;  // refused: fine
    const Camera& c = scene->cameras[0];
    glm::dvec3 forward = glm::normalize(c.target - c.position);
    glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
    EXPECT_TRUE(std::isfinite(right.x) && std::isfinite(right.y) && std::isfinite(right.z))
        << "accepted camera target " << dx << " has a NaN/inf basis";
  }
}

TEST(SceneJsonTest, TopLevelMustBeAnObject) {
  EXPECT_TRUE(refused("[]", {"object"}));
  EXPECT_TRUE(refused("42", {"object"}));
  EXPECT_TRUE(refused("null", {"object"}));
}

// ---- validateScene on an in-memory Scene --------------------------------------------------

TEST(SceneValidateTest, NamesTheField) {
  auto base = parseSceneJson(baseSceneJson().dump());
  ASSERT_TRUE(base.ok());
  ASSERT_TRUE(validateScene(*base).ok());
  auto expectInvalid = [&](const std::function<void(Scene&)>& mutate, const std::string& needle) {
    Scene s = *base;
    mutate(s);
    Status status = validateScene(s);
    ASSERT_FALSE(status.ok()) << needle;
    EXPECT_NE(status.message().find(needle), std::string::npos) << status.message();
  };
  expectInvalid([](Scene& s) { s.size[1] = 0; }, "size[1]");
  expectInvalid([](Scene& s) { s.size[0] = 257; }, "size[0]");
  expectInvalid([](Scene& s) { s.palette[1].color[0] = 300; }, "palette[1].color");
  expectInvalid([](Scene& s) { s.palette[0].roughness = 8; }, "palette[0]");
  expectInvalid([](Scene& s) { s.palette.resize(256); }, "palette");
  expectInvalid([](Scene& s) { s.blocks["stone"].voxels.resize(100); }, "blocks.stone");
  expectInvalid([](Scene& s) { s.blocks["ball"].voxels[77] = 9; }, "voxel 77");
  expectInvalid([](Scene& s) { s.placements[2].at[2] = 4; }, "placements[2].at[2]");
  expectInvalid([](Scene& s) { s.placements[1].block = "nope"; }, "placements[1].block");
  expectInvalid([](Scene& s) { s.placements[0].rot = 24; }, "placements[0].rot");
  expectInvalid([](Scene& s) { s.placements[2].at = s.placements[0].at; }, "placements[2].at");
  expectInvalid([](Scene& s) { s.sun->direction = glm::dvec3(0.0); }, "sun.direction");
  expectInvalid([](Scene& s) { s.sun->direction.x = NAN; }, "sun.direction");
  expectInvalid([](Scene& s) { s.sun->irradiance.y = 1e6; }, "sun.irradiance");
  expectInvalid([](Scene& s) { s.sun->angular_radius_deg = 0.001; }, "sun.angular_radius_deg");
  expectInvalid([](Scene& s) { s.sky.horizon.z = -1; }, "sky");
  expectInvalid([](Scene& s) { s.emission_scale = INFINITY; }, "emission_scale");
  expectInvalid([](Scene& s) { s.ambient.x = NAN; }, "ambient");
  expectInvalid([](Scene& s) { s.bake.spp = 0; }, "bake.spp");
  expectInvalid([](Scene& s) { s.bake.max_bounces = 65; }, "bake.max_bounces");
  expectInvalid([](Scene& s) { s.bake.max_hemisphere = 48; }, "bake.max_hemisphere");
  expectInvalid([](Scene& s) { s.cameras[0].fov_deg = 180; }, "cameras[0].fov_deg");
  expectInvalid(
      [](Scene& s) { s.cameras[0].target = s.cameras[0].position + glm::dvec3(0, -1, 0); },
      "cameras[0]");
}

// ---- Round trip and built-in scenes -------------------------------------------------------

TEST(SceneRoundTripTest, BaseSceneRoundTrips) {
  auto scene = parseSceneJson(baseSceneJson().dump());
  ASSERT_TRUE(scene.ok());
  std::string text = sceneToJson(*scene);
  auto again = parseSceneJson(text);
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(*again, *scene);
  EXPECT_EQ(sceneToJson(*again), text);  // the writer is a fixed point
}

TEST(SceneRoundTripTest, SavedFileIsTheDocumentWrittenInPieces) {
  auto scene = parseSceneJson(baseSceneJson().dump());
  ASSERT_TRUE(scene.ok());
  scene->size = {24, 24, 24};
  scene->placements.clear();
  for (int i = 0; i < 24 * 24 * 24; ++i)  // about 0.6 MB: ten pieces of the streamed write
    scene->placements.push_back({{i % 24, (i / 24) % 24, i / 576}, "stone", i % 24});
  ASSERT_TRUE(validateScene(*scene).ok()) << validateScene(*scene).message();
  const std::string path =
      (fs::temp_directory_path() / ("rdm_scene_save_" + std::to_string(getpid()) + ".json"))
          .string();
  ASSERT_TRUE(saveSceneFile(path, *scene).ok());
  auto saved = readFileToString(path);
  ASSERT_TRUE(saved.ok());
  const std::string text = sceneToJson(*scene);
  EXPECT_EQ(*saved, text);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  size_t lines = 0;
  for (size_t at = text.find("{\"at\": ["); at != std::string::npos;
       at = text.find("{\"at\": [", at + 1))
    ++lines;
  EXPECT_EQ(lines, scene->placements.size()) << "one placement a line";
  auto again = loadSceneFile(path);
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(*again, *scene);
  fs::remove(path);
}

TEST(SceneRoundTripTest, AwkwardDoublesRoundTripExactly) {
  auto scene = parseSceneJson(baseSceneJson().dump());
  ASSERT_TRUE(scene.ok());
  scene->sun->direction = {0.1, 1.0 / 3.0, -1e-300};
  scene->sun->irradiance = {std::nextafter(1e5, 0.0), 5e-324, 0.0};
  scene->sky.zenith = {0.7, 1e-17, 12345.678901234567};
  scene->emission_scale = 2.0 / 3.0;
  scene->cameras[0].position = {-999999.9999999999, 1e-310, 0.30000000000000004};
  scene->bake.seed = 4294967295u;
  ASSERT_TRUE(validateScene(*scene).ok());
  auto again = parseSceneJson(sceneToJson(*scene));
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(*again, *scene);
}

TEST(SceneRoundTripTest, EveryBuiltinRoundTripsAndValidates) {
  auto names = builtinSceneNames();
  EXPECT_GE(names.size(), 2u);
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    auto scene = builtinScene(name);
    ASSERT_TRUE(scene.ok()) << scene.error();
    Status status = validateScene(*scene);
    EXPECT_TRUE(status.ok()) << status.message();
    std::string text = sceneToJson(*scene);
    auto parsed = parseSceneJson(text);
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    EXPECT_EQ(*parsed, *scene);
    // sceneToJson(parse(x)) parses back to an equal scene.
    auto again = parseSceneJson(sceneToJson(*parsed));
    ASSERT_TRUE(again.ok()) << again.error();
    EXPECT_EQ(*again, *parsed);
    // Built-ins are pure functions of their name.
    EXPECT_EQ(*builtinScene(name), *scene);
    // loadSceneByNameOrPath resolves the name.
    auto by_name = loadSceneByNameOrPath(name);
    ASSERT_TRUE(by_name.ok()) << by_name.error();
    EXPECT_EQ(*by_name, *scene);
  }
}

TEST(SceneBuiltinTest, UnknownBuiltinIsNamed) {
  auto scene = builtinScene("atlantis");
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.error().find("atlantis"), std::string::npos) << scene.error();
}

int nonEmptyPlacements(const Scene& s) {
  int count = 0;
  for (const Placement& p : s.placements) {
    const auto& voxels = s.blocks.at(p.block).voxels;
    for (uint8_t v : voxels) {
      if (v) {
        ++count;
        break;
      }
    }
  }
  return count;
}

bool hasMetallicMirrorInUse(const Scene& s) {
  std::set<int> used;
  for (const Placement& p : s.placements)
    for (uint8_t v : s.blocks.at(p.block).voxels) used.insert(v);
  for (size_t i = 0; i < s.palette.size(); ++i) {
    const PaletteEntry& e = s.palette[i];
    if (e.metallic == 3 && e.roughness == 0 && used.count(int(i) + 1)) return true;
  }
  return false;
}

TEST(SceneBuiltinTest, IslandShape) {
  auto scene = builtinScene("island");
  ASSERT_TRUE(scene.ok());
  int blocks = nonEmptyPlacements(*scene);
  EXPECT_GE(blocks, 140);
  EXPECT_LE(blocks, 180);
  VoxelWorld world = buildWorld(*scene);
  EXPECT_FALSE(world.emitters.empty());
  EXPECT_TRUE(hasMetallicMirrorInUse(*scene));
  EXPECT_GE(scene->cameras.size(), 2u);
  // Every non-empty placement lands in a slot of the compiled world.
  int occupied = 0;
  for (int32_t b : world.slots) occupied += b >= 0;
  EXPECT_EQ(occupied, blocks);
}

TEST(SceneBuiltinTest, ChessShape) {
  auto scene = builtinScene("chess");
  ASSERT_TRUE(scene.ok());
  EXPECT_EQ(nonEmptyPlacements(*scene), 80);
  EXPECT_EQ(scene->placements.size(), 80u);
  // 64 tiles on the bottom layer, 16 pieces above.
  int tiles = 0, pieces = 0;
  for (const Placement& p : scene->placements) (p.at[1] == 0 ? tiles : pieces)++;
  EXPECT_EQ(tiles, 64);
  EXPECT_EQ(pieces, 16);
  EXPECT_TRUE(scene->sun.has_value());
  for (const PaletteEntry& e : scene->palette) EXPECT_EQ(e.emission, 0);
  VoxelWorld world = buildWorld(*scene);
  EXPECT_TRUE(world.emitters.empty());
  EXPECT_TRUE(world.sun.present);
  EXPECT_GE(scene->cameras.size(), 2u);
}

// ---- Files --------------------------------------------------------------------------------

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("rdm_scene_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_))
      names.push_back(e.path().filename().string());
    return names;
  }
  fs::path dir_;
};

TEST_F(SceneFileTest, SaveIsAtomicAndLoadsBack) {
  auto chess = builtinScene("chess");
  ASSERT_TRUE(chess.ok());
  const std::string path = (dir_ / "chess.json").string();
  Status saved = saveSceneFile(path, *chess);
  ASSERT_TRUE(saved.ok()) << saved.message();
  EXPECT_EQ(entries(), std::vector<std::string>{"chess.json"});  // no .tmp left behind
  auto loaded = loadSceneFile(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  EXPECT_EQ(*loaded, *chess);
  // Overwriting replaces the whole file, again leaving nothing else.
  auto furnace = builtinScene("furnace");
  ASSERT_TRUE(furnace.ok());
  ASSERT_TRUE(saveSceneFile(path, *furnace).ok());
  EXPECT_EQ(entries(), std::vector<std::string>{"chess.json"});
  auto reloaded = loadSceneFile(path);
  ASSERT_TRUE(reloaded.ok()) << reloaded.error();
  EXPECT_EQ(*reloaded, *furnace);
  auto by_path = loadSceneByNameOrPath(path);
  ASSERT_TRUE(by_path.ok()) << by_path.error();
  EXPECT_EQ(*by_path, *furnace);
}

TEST_F(SceneFileTest, SaveIntoMissingDirectoryFailsNamingPath) {
  auto furnace = builtinScene("furnace");
  ASSERT_TRUE(furnace.ok());
  const std::string path = (dir_ / "no_such_dir" / "scene.json").string();
  Status saved = saveSceneFile(path, *furnace);
  ASSERT_FALSE(saved.ok());
  EXPECT_NE(saved.message().find(path), std::string::npos) << saved.message();
  EXPECT_TRUE(entries().empty());
}

TEST_F(SceneFileTest, LoadMissingFileNamesPath) {
  const std::string path = (dir_ / "missing.json").string();
  auto scene = loadSceneFile(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.error().find(path), std::string::npos) << scene.error();
  auto by_name = loadSceneByNameOrPath(path);
  ASSERT_FALSE(by_name.ok());
  EXPECT_NE(by_name.error().find(path), std::string::npos) << by_name.error();
}

TEST_F(SceneFileTest, LoadBadFileNamesPathAndField) {
  const std::string path = (dir_ / "bad.json").string();
  json j = baseSceneJson();
  j["bake"]["spp"] = 0;
  std::ofstream(path) << j.dump();
  auto scene = loadSceneFile(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.error().find(path), std::string::npos) << scene.error();
  EXPECT_NE(scene.error().find("bake.spp"), std::string::npos) << scene.error();
}

// ---- sRGB decoding (docs/spec.md section 1) against tests/data/srgb.json
// ---------------------------

TEST(SceneSrgbTest, MatchesKnownAnswers) {
  std::ifstream in(std::string(RDM_TEST_DATA_DIR) + "/srgb.json");
  ASSERT_TRUE(in.good());
  json j = json::parse(in);
  const json& linear = j.at("linear");
  ASSERT_EQ(linear.size(), 256u);
  for (int v = 0; v < 256; ++v) {
    double expected = linear[v].get<double>();
    double got = srgbToLinear(v);
    EXPECT_LE(std::abs(got - expected), 1e-7 * expected)
        << "value " << v << ": " << got << " vs " << expected;
  }
  EXPECT_EQ(srgbToLinear(0), 0.0f);
  EXPECT_EQ(srgbToLinear(255), 1.0f);
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

json withCameras(const json& cameras) {
  json j = baseSceneJson();
  j["cameras"] = cameras;
  return j;
}

json cameraJson(const std::string& name) {
  json c = {{"position", {-2.0, 5.0, -2.0}}, {"target", {4.0, 1.0, 4.0}}};
  if (!name.empty()) c["name"] = name;
  return c;
}

TEST(SceneCameras, NamesRoundTripAndAreFoundByNameOrIndex) {
  auto scene =
      parseSceneJson(withCameras(json::array({cameraJson("front"), cameraJson("")})).dump());
  ASSERT_TRUE(scene) << scene.error();
  EXPECT_EQ(scene->cameras[0].name, "front");
  auto again = parseSceneJson(sceneToJson(*scene));
  ASSERT_TRUE(again) << again.error();
  EXPECT_EQ(*again, *scene);
  EXPECT_EQ(sceneToJson(*scene).find("\"name\": \"\""), std::string::npos);
  EXPECT_EQ(*findCamera(*scene, "front"), 0u);
  EXPECT_EQ(*findCamera(*scene, "1"), 1u);
  auto missing = findCamera(*scene, "back");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("0 (front), 1"), std::string::npos) << missing.error();
  EXPECT_FALSE(findCamera(*scene, "2"));
}

TEST(SceneCameras, DuplicateOrNumericOrOddNamesAreRefusedNamingTheCamera) {
  auto twice =
      parseSceneJson(withCameras(json::array({cameraJson("top"), cameraJson("top")})).dump());
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().find("cameras[1].name"), std::string::npos) << twice.error();
  for (const char* bad : {"12", "a b", "x/y"}) {
    auto scene = parseSceneJson(withCameras(json::array({cameraJson(bad)})).dump());
    ASSERT_FALSE(scene) << bad;
    EXPECT_NE(scene.error().find("cameras[0].name"), std::string::npos) << scene.error();
  }
  json not_string = withCameras(json::array({cameraJson("")}));
  not_string["cameras"][0]["name"] = 3;
  EXPECT_FALSE(parseSceneJson(not_string.dump()));
}

}  // namespace
}  // namespace rdm
