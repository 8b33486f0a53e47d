// Every malformed input class of the scene loader is refused with a message naming the
// field path or byte offset (docs/spec.md section 2's ranges, references and payloads).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/base/base64.h"
#include "rdm/scene/scene.h"
#include "scene_fixtures.h"

namespace rdm {
namespace {

using nlohmann::json;
using namespace rdm::test;

// One malformed input: a mutation of the base scene and what its message must contain.
struct RefusalCase {
  std::string name;
  std::function<void(json&)> mutate;
  std::vector<std::string> needles;
};

void PrintTo(const RefusalCase& c, std::ostream* os) {
  *os << c.name;
}

class SceneRefusalTest : public ::testing::TestWithParam<RefusalCase> {};

TEST_P(SceneRefusalTest, RefusedWithFieldInMessage) {
  json j = baseSceneJson();
  ASSERT_TRUE(parseSceneJson(j.dump()).ok());
  GetParam().mutate(j);
  EXPECT_TRUE(refused(j.dump(), GetParam().needles));
}

// The field a message names is also the Status's data, with a code, so the daemon maps the
// refusal to HTTP without reading the text.
TEST_P(SceneRefusalTest, FieldAndCodeAreData) {
  json j = baseSceneJson();
  GetParam().mutate(j);
  auto scene = parseSceneJson(j.dump());
  ASSERT_FALSE(scene.ok());
  const Status& status = scene.status();
  EXPECT_NE(status.code(), StatusCode::kInternal) << status.message();
  const std::string& message = status.message();
  const std::string prefix = "field '";
  if (message.rfind(prefix, 0) != 0) {
    EXPECT_TRUE(status.field().empty()) << message;
    return;
  }
  EXPECT_EQ(status.code(), StatusCode::kInvalidInput) << message;
  const size_t end = message.find('\'', prefix.size());
  ASSERT_NE(end, std::string::npos) << message;
  EXPECT_EQ(status.field(), message.substr(prefix.size(), end - prefix.size()));
}

std::string voxelsWith(size_t index, uint8_t value) {
  std::vector<uint8_t> voxels = ballVoxels();
  voxels[index] = value;
  return base64Encode(voxels);
}

std::string withCharAt(std::string text, size_t offset, char c) {
  text[offset] = c;
  return text;
}

const RefusalCase kRefusals[] = {
    // Unknown keys, top level and nested: the message names the full path.
    {"UnknownTopLevelKey", [](json& j) { j["colour"] = 1; }, {"'colour'", "unknown key"}},
    {"UnknownSunKey",
     [](json& j) {
       j["sun"]["colour"] = {1, 1, 1};
     },
     {"sun.colour", "unknown key"}},
    {"UnknownPaletteKey",
     [](json& j) { j["palette"][0]["shiny"] = true; },
     {"palette[0].shiny", "unknown key"}},
    {"UnknownPaletteKeySecond",
     [](json& j) { j["palette"][1]["alpha"] = 1; },
     {"palette[1].alpha"}},
    {"UnknownBlockKey", [](json& j) { j["blocks"]["stone"]["tint"] = 2; }, {"blocks.stone.tint"}},
    {"UnknownPlacementKey",
     [](json& j) { j["placements"][1]["flip"] = true; },
     {"placements[1].flip"}},
    {"UnknownSkyKey",
     [](json& j) {
       j["sky"]["nadir"] = {0, 0, 0};
     },
     {"sky.nadir"}},
    {"UnknownBakeKey", [](json& j) { j["bake"]["threads"] = 4; }, {"bake.threads"}},
    {"UnknownCameraKey", [](json& j) { j["cameras"][0]["zoom"] = 2; }, {"cameras[0].zoom"}},
    // Wrong types.
    {"SizeNotArray", [](json& j) { j["size"] = "big"; }, {"'size'"}},
    {"SizeTwoAxes",
     [](json& j) {
       j["size"] = {4, 4};
     },
     {"'size'", "array of 3"}},
    {"SizeFloat", [](json& j) { j["size"][1] = 2.5; }, {"size[1]", "integer"}},
    {"PaletteNotArray", [](json& j) { j["palette"] = json::object(); }, {"palette", "array"}},
    {"PaletteEntryNotObject", [](json& j) { j["palette"][1] = 5; }, {"palette[1]", "object"}},
    {"RoughnessString",
     [](json& j) { j["palette"][0]["roughness"] = "7"; },
     {"palette[0].roughness", "integer"}},
    {"RoughnessFloat",
     [](json& j) { j["palette"][0]["roughness"] = 1.5; },
     {"palette[0].roughness", "integer"}},
    {"ColorNotArray", [](json& j) { j["palette"][0]["color"] = "red"; }, {"palette[0].color"}},
    {"BlocksNotObject", [](json& j) { j["blocks"] = json::array(); }, {"blocks", "object"}},
    {"FillString",
     [](json& j) { j["blocks"]["stone"]["fill"] = "1"; },
     {"blocks.stone.fill", "integer"}},
    {"VoxelsNotString",
     [](json& j) { j["blocks"]["ball"]["voxels"] = 5; },
     {"blocks.ball.voxels", "base64"}},
    {"PlacementsNotArray", [](json& j) { j["placements"] = 1; }, {"placements", "array"}},
    {"AtNotArray", [](json& j) { j["placements"][0]["at"] = 0; }, {"placements[0].at"}},
    {"AtString",
     [](json& j) { j["placements"][0]["at"][1] = "0"; },
     {"placements[0].at[1]", "integer"}},
    {"BlockNameNumber", [](json& j) { j["placements"][0]["block"] = 3; }, {"placements[0].block"}},
    {"RotFloat",
     [](json& j) { j["placements"][1]["rot"] = 1.0; },
     {"placements[1].rot", "integer"}},
    {"SunString", [](json& j) { j["sun"] = "bright"; }, {"'sun'", "object"}},
    {"SunDirectionShort",
     [](json& j) {
       j["sun"]["direction"] = {1, 2};
     },
     {"sun.direction"}},
    {"SunIrradianceString",
     [](json& j) { j["sun"]["irradiance"][2] = "x"; },
     {"sun.irradiance[2]", "number"}},
    {"EmissionScaleString",
     [](json& j) { j["emission_scale"] = "8"; },
     {"emission_scale", "number"}},
    {"AmbientScalar", [](json& j) { j["ambient"] = 0.2; }, {"ambient"}},
    {"BakeNotObject", [](json& j) { j["bake"] = 256; }, {"bake", "object"}},
    {"SppFloat", [](json& j) { j["bake"]["spp"] = 16.5; }, {"bake.spp", "integer"}},
    {"CamerasNotArray", [](json& j) { j["cameras"] = json::object(); }, {"cameras", "array"}},
    {"FovString",
     [](json& j) { j["cameras"][0]["fov_deg"] = "50"; },
     {"cameras[0].fov_deg", "number"}},
    {"SkyNull", [](json& j) { j["sky"] = nullptr; }, {"sky", "object"}},
    // Out of range: each range of docs/spec.md section 2's table at least once.
    {"SizeZero", [](json& j) { j["size"][0] = 0; }, {"size[0]"}},
    {"Size257", [](json& j) { j["size"][2] = 257; }, {"size[2]"}},
    {"SizeNegative", [](json& j) { j["size"][1] = -3; }, {"size[1]"}},
    {"Spp0", [](json& j) { j["bake"]["spp"] = 0; }, {"bake.spp"}},
    {"Spp65537", [](json& j) { j["bake"]["spp"] = 65537; }, {"bake.spp"}},
    {"MaxBounces65", [](json& j) { j["bake"]["max_bounces"] = 65; }, {"bake.max_bounces"}},
    {"MaxBouncesNegative", [](json& j) { j["bake"]["max_bounces"] = -1; }, {"bake.max_bounces"}},
    {"MaxHemisphere3",
     [](json& j) { j["bake"]["max_hemisphere"] = 3; },
     {"bake.max_hemisphere", "power of two"}},
    {"MaxHemisphere512",
     [](json& j) { j["bake"]["max_hemisphere"] = 512; },
     {"bake.max_hemisphere"}},
    {"MaxHemisphere1", [](json& j) { j["bake"]["max_hemisphere"] = 1; }, {"bake.max_hemisphere"}},
    {"MaxHemisphere96",
     [](json& j) { j["bake"]["max_hemisphere"] = 96; },
     {"bake.max_hemisphere", "power of two"}},
    {"SeedNegative", [](json& j) { j["bake"]["seed"] = -1; }, {"bake.seed"}},
    {"FaceLightSppNegative",
     [](json& j) { j["bake"]["face_light_spp"] = -1; },
     {"bake.face_light_spp"}},
    {"FaceLightSpp65537",
     [](json& j) { j["bake"]["face_light_spp"] = 65537; },
     {"bake.face_light_spp"}},
    {"Seed2To32", [](json& j) { j["bake"]["seed"] = 4294967296LL; }, {"bake.seed"}},
    {"SeedHuge", [](json& j) { j["bake"]["seed"] = 18446744073709551615ULL; }, {"bake.seed"}},
    {"Roughness8", [](json& j) { j["palette"][0]["roughness"] = 8; }, {"palette[0].roughness"}},
    {"Metallic4", [](json& j) { j["palette"][1]["metallic"] = 4; }, {"palette[1].metallic"}},
    {"Emission4", [](json& j) { j["palette"][0]["emission"] = 4; }, {"palette[0].emission"}},
    {"EmissionNegative",
     [](json& j) { j["palette"][0]["emission"] = -1; },
     {"palette[0].emission"}},
    {"Color256", [](json& j) { j["palette"][0]["color"][1] = 256; }, {"palette[0].color[1]"}},
    {"ColorNegative", [](json& j) { j["palette"][1]["color"][2] = -1; }, {"palette[1].color[2]"}},
    {"ColorTwoChannels",
     [](json& j) {
       j["palette"][1]["color"] = {1, 2};
     },
     {"palette[1].color"}},
    {"Irradiance1e6", [](json& j) { j["sun"]["irradiance"][0] = 1e6; }, {"sun.irradiance[0]"}},
    {"IrradianceNegative",
     [](json& j) { j["sun"]["irradiance"][1] = -0.5; },
     {"sun.irradiance[1]"}},
    {"AngularRadiusTiny",
     [](json& j) { j["sun"]["angular_radius_deg"] = 0.001; },
     {"sun.angular_radius_deg"}},
    {"AngularRadius11",
     [](json& j) { j["sun"]["angular_radius_deg"] = 11; },
     {"sun.angular_radius_deg"}},
    {"SunDirectionZero",
     [](json& j) {
       j["sun"]["direction"] = {0, 0.0, 0};
     },
     {"sun.direction"}},
    {"SkyNegative", [](json& j) { j["sky"]["zenith"][0] = -0.1; }, {"sky.zenith[0]"}},
    {"SkyTooBright", [](json& j) { j["sky"]["ground"][2] = 2e5; }, {"sky.ground[2]"}},
    {"EmissionScaleNegative", [](json& j) { j["emission_scale"] = -1; }, {"emission_scale"}},
    {"EmissionScaleTooLarge", [](json& j) { j["emission_scale"] = 1e6; }, {"emission_scale"}},
    {"AmbientNegative", [](json& j) { j["ambient"][1] = -1; }, {"ambient[1]"}},
    {"AmbientTooLarge", [](json& j) { j["ambient"][0] = 1.5e5; }, {"ambient[0]"}},
    {"Rot24", [](json& j) { j["placements"][1]["rot"] = 24; }, {"placements[1].rot"}},
    {"RotNegative", [](json& j) { j["placements"][0]["rot"] = -1; }, {"placements[0].rot"}},
    {"Fov180", [](json& j) { j["cameras"][0]["fov_deg"] = 180; }, {"cameras[0].fov_deg"}},
    {"Fov0", [](json& j) { j["cameras"][0]["fov_deg"] = 0; }, {"cameras[0].fov_deg"}},
    {"FovNegative", [](json& j) { j["cameras"][0]["fov_deg"] = -10; }, {"cameras[0].fov_deg"}},
    {"CameraStraightDown",
     [](json& j) {
       j["cameras"][0]["target"] = {-2.0, 0.0, -2.0};
     },
     {"cameras[0]", "parallel"}},
    {"CameraStraightUp",
     [](json& j) {
       j["cameras"].push_back({{"position", {1, 0, 1}}, {"target", {1, 9, 1}}});
     },
     {"cameras[1]", "parallel"}},
    {"CameraTargetIsPosition",
     [](json& j) { j["cameras"][0]["target"] = j["cameras"][0]["position"]; },
     {"cameras[0]"}},
    {"CameraFarAway",
     [](json& j) { j["cameras"][0]["position"][0] = 1e7; },
     {"cameras[0].position[0]"}},
    // Palette index past the palette (2 entries).
    {"FillPastPalette",
     [](json& j) { j["blocks"]["stone"]["fill"] = 3; },
     {"blocks.stone.fill", "palette index 3"}},
    {"Fill256", [](json& j) { j["blocks"]["stone"]["fill"] = 256; }, {"blocks.stone.fill"}},
    {"VoxelPastPalette",
     [](json& j) { j["blocks"]["ball"]["voxels"] = voxelsWith(1234, 3); },
     {"blocks.ball.voxels", "voxel 1234", "palette index 3"}},
    {"VoxelPastPaletteLast",
     [](json& j) { j["blocks"]["ball"]["voxels"] = voxelsWith(4095, 255); },
     {"blocks.ball.voxels", "voxel 4095"}},
    {"VoxelsWithEmptyPalette",
     [](json& j) {
       j["palette"] = json::array();
       j["blocks"].erase("stone");
       j["placements"].erase(0);
     },
     {"blocks.ball.voxels", "voxel 0", "palette index 1"}},
    {"PaletteOver255",
     [](json& j) {
       for (int i = 0; i < 254; ++i) j["palette"].push_back({{"color", {1, 2, 3}}});
     },
     {"palette", "255"}},
    // Placements outside the grid (size 4 x 3 x 4).
    {"PlacementXOutside",
     [](json& j) { j["placements"][1]["at"][0] = 4; },
     {"placements[1].at[0]", "outside the grid"}},
    {"PlacementYOutside",
     [](json& j) { j["placements"][2]["at"][1] = 3; },
     {"placements[2].at[1]"}},
    {"PlacementZNegative",
     [](json& j) { j["placements"][0]["at"][2] = -1; },
     {"placements[0].at[2]"}},
    {"PlacementHuge",
     [](json& j) { j["placements"][0]["at"][0] = 1LL << 40; },
     {"placements[0].at[0]"}},
    {"DuplicateSlot",
     [](json& j) {
       j["placements"][2]["at"] = {1, 0, 0};
     },
     {"placements[2].at", "already"}},
    {"UnknownBlockName",
     [](json& j) { j["placements"][1]["block"] = "marble"; },
     {"placements[1].block", "marble"}},
    // Voxel payload.
    {"PayloadShort",
     [](json& j) { j["blocks"]["ball"]["voxels"] = base64Encode(std::vector<uint8_t>(4095, 1)); },
     {"blocks.ball.voxels", "4095", "4096"}},
    {"PayloadLong",
     [](json& j) { j["blocks"]["ball"]["voxels"] = base64Encode(std::vector<uint8_t>(4097, 1)); },
     {"blocks.ball.voxels", "4097"}},
    {"PayloadEmpty",
     [](json& j) { j["blocks"]["ball"]["voxels"] = ""; },
     {"blocks.ball.voxels", "0 bytes"}},
    {"Base64BadChar",
     [](json& j) { j["blocks"]["ball"]["voxels"] = withCharAt(voxelsWith(0, 0), 100, '!'); },
     {"blocks.ball.voxels", "offset 100"}},
    {"Base64UrlAlphabet",
     [](json& j) { j["blocks"]["ball"]["voxels"] = withCharAt(voxelsWith(0, 0), 5000, '-'); },
     {"blocks.ball.voxels", "offset 5000"}},
    {"Base64LineBreak",
     [](json& j) {
       std::string s = voxelsWith(0, 0);
       j["blocks"]["ball"]["voxels"] = s.substr(0, 76) + "\n" + s.substr(76);
     },
     {"blocks.ball.voxels", "length"}},
    {"Base64MisplacedPad",
     [](json& j) { j["blocks"]["ball"]["voxels"] = withCharAt(voxelsWith(0, 0), 8, '='); },
     {"blocks.ball.voxels", "offset 8"}},
    {"Base64BadLength",
     [](json& j) { j["blocks"]["ball"]["voxels"] = voxelsWith(0, 0) + "A"; },
     {"blocks.ball.voxels", "length"}},
    {"FillAndVoxels",
     [](json& j) { j["blocks"]["stone"]["voxels"] = voxelsWith(0, 0); },
     {"blocks.stone", "exactly one"}},
    {"NeitherFillNorVoxels",
     [](json& j) { j["blocks"]["stone"] = json::object(); },
     {"blocks.stone", "exactly one"}},
    {"EmptyBlockName",
     [](json& j) {
       j["blocks"][""] = {{"fill", 1}};
     },
     {"blocks", "empty block name"}},
    // Missing required fields.
    {"MissingSize", [](json& j) { j.erase("size"); }, {"size", "required"}},
    {"MissingColor",
     [](json& j) { j["palette"][1].erase("color"); },
     {"palette[1].color", "required"}},
    {"MissingAt",
     [](json& j) { j["placements"][2].erase("at"); },
     {"placements[2].at", "required"}},
    {"MissingBlock", [](json& j) { j["placements"][0].erase("block"); }, {"placements[0].block"}},
    {"MissingSunDirection",
     [](json& j) { j["sun"].erase("direction"); },
     {"sun.direction", "required"}},
    {"MissingCameraPosition",
     [](json& j) { j["cameras"][0].erase("position"); },
     {"cameras[0].position", "required"}},
    {"MissingCameraTarget",
     [](json& j) { j["cameras"][0].erase("target"); },
     {"cameras[0].target", "required"}},
    // Format and version.
    {"MissingFormat", [](json& j) { j.erase("format"); }, {"format", "rdm-scene"}},
    {"WrongFormat", [](json& j) { j["format"] = "rdm-atlas"; }, {"format", "rdm-scene"}},
    {"FormatNumber", [](json& j) { j["format"] = 1; }, {"format"}},
    {"MissingVersion", [](json& j) { j.erase("version"); }, {"version"}},
    {"Version2", [](json& j) { j["version"] = 2; }, {"version", "1"}},
    {"VersionString", [](json& j) { j["version"] = "1"; }, {"version"}},
    {"VersionFloat", [](json& j) { j["version"] = 1.5; }, {"version"}},
};

INSTANTIATE_TEST_SUITE_P(Scene, SceneRefusalTest, ::testing::ValuesIn(kRefusals),
                         [](const ::testing::TestParamInfo<RefusalCase>& info) {
                           return info.param.name;
                         });

TEST(SceneJsonTest, RefusalNamesTheFirstBadPlacementIndex) {
  // A later placement's error names its own index, not the first one's.
  json j = baseSceneJson();
  for (int i = 0; i < 20; ++i)
    j["placements"].push_back({{"at", {i % 4, 1, i / 4 % 4}}, {"block", "stone"}});
  j["placements"][17]["at"][1] = 7;
  EXPECT_TRUE(refused(j.dump(), {"placements[17].at[1]", "7"}));
}

TEST(SceneJsonTest, RefusalDoesNotDependOnKeyOrder) {
  // Blocks parse after the palette even when written first; placements after blocks.
  json j = baseSceneJson();
  std::string text = "{\"placements\": " + j["placements"].dump() +
                     ", \"blocks\": " + j["blocks"].dump() +
                     ", \"palette\": " + j["palette"].dump() +
                     ", \"size\": [4, 3, 4], \"version\": 1, \"format\": \"rdm-scene\"}";
  auto scene = parseSceneJson(text);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->placements.size(), 3u);
}

}  // namespace
}  // namespace rdm
