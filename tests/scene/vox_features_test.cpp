// MagicaVoxel import of what the author set up: cameras, animation frames, layers, the file's
// light, the ground, and malformed chunks of each (files built byte by byte).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "cli_run.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/vox_import.h"
#include "rdm/scene/world.h"
#include "vox_bytes.h"

namespace rdm {
namespace {

using Items = test::VoxItems;
using test::chunk;
using test::dict;
using test::model;
using test::put32;
using test::str;

std::string file(const std::string& children) {
  std::string main = "MAIN";
  put32(main, 0);
  put32(main, int32_t(children.size()));
  std::string f = "VOX ";
  put32(f, 200);
  return f + main + children;
}

std::string idDict(const char* id, int32_t n, const Items& items) {
  std::string c;
  put32(c, n);
  return chunk(id, c + dict(items));
}

// nTRN with one dictionary per keyframe.
std::string transform(int id, int child, int layer, const std::vector<Items>& frames) {
  std::string c;
  put32(c, id);
  c += dict({});
  for (int32_t v : {child, -1, layer, int32_t(frames.size())}) put32(c, v);
  for (const Items& f : frames) c += dict(f);
  return chunk("nTRN", c);
}

std::string group(int id, const std::vector<int>& children) {
  std::string c;
  put32(c, id);
  c += dict({});
  put32(c, int32_t(children.size()));
  for (int child : children) put32(c, child);
  return chunk("nGRP", c);
}

// nSHP with (model id, attributes) per keyframe.
std::string shape(int id, const std::vector<std::pair<int, Items>>& models) {
  std::string c;
  put32(c, id);
  c += dict({});
  put32(c, int32_t(models.size()));
  for (const auto& [m, attributes] : models) {
    put32(c, m);
    c += dict(attributes);
  }
  return chunk("nSHP", c);
}

std::string pack(int32_t n) {
  std::string c;
  put32(c, n);
  return chunk("PACK", c);
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

std::string lines(const std::vector<std::string>& v) {
  std::string all;
  for (const std::string& line : v) all += line + "\n";
  return all;
}

// --- cameras ---

// A 4 x 4 x 4 model (MagicaVoxel z up) filling y >= 1, plus one voxel at (1, 0, 1): only on
// its front, the -Y side, which the import turns into the scene's +Z side.
std::string frontMarked() {
  std::vector<std::array<uint8_t, 4>> voxels{{1, 0, 1, 2}};
  for (uint8_t x = 0; x < 4; ++x)
    for (uint8_t y = 1; y < 4; ++y)
      for (uint8_t z = 0; z < 4; ++z) voxels.push_back({x, y, z, 1});
  return model({4, 4, 4}, voxels);
}

TEST(VoxCameras, DefaultAndFrontSeeTheFrontBackDoesNot) {
  auto scene = importVox(file(frontMarked()));
  ASSERT_TRUE(scene.ok()) << scene.error();
  // MagicaVoxel (1, 0, 1) -> scene (1, 1, 4 - 1 - 0): its centre, in blocks.
  const glm::dvec3 marked = glm::dvec3(1.5, 1.5, 3.5) / 16.0;
  EXPECT_NE(buildWorld(*scene).voxelAt({1, 1, 3}), 0);
  const glm::dvec3 centre = glm::dvec3(2.0, 2.0, 2.0) / 16.0;
  ASSERT_EQ(scene->cameras[0].name, "default");
  for (const char* name : {"default", "front", "back", "left", "right", "top", "iso"}) {
    auto index = findCamera(*scene, name);
    ASSERT_TRUE(index.ok()) << index.error();
    const Camera& c = scene->cameras[*index];
    EXPECT_TRUE(cameraUsable(c)) << name;
    EXPECT_LT(glm::length(c.target - centre), 1e-9) << name;
    const glm::dvec3 forward = glm::normalize(c.target - c.position);
    const double angle = std::acos(glm::dot(glm::normalize(marked - c.position), forward));
    EXPECT_LT(angle, glm::radians(c.fov_deg) * 0.5) << name;  // in the view
    const bool nearer = glm::length(marked - c.position) < glm::length(centre - c.position);
    const std::string n = name;
    if (n == "default" || n == "front" || n == "back") {
      EXPECT_EQ(nearer, n != "back") << name;
    }
  }
  const Camera& top = scene->cameras[*findCamera(*scene, "top")];
  EXPECT_GT(glm::normalize(top.position - top.target).y, 0.99);
}

TEST(VoxCameras, SavedCamerasConvertAndDefaultOnesAreReported) {
  VoxImportReport report;
  const Items saved{{"_mode", "pers"},
                    {"_focus", "2 2 2"},
                    {"_angle", "30 0 0"},
                    {"_radius", "40"},
                    {"_fov", "45"}};
  const Items unset{{"_mode", "pers"},
                    {"_focus", "0 0 0"},
                    {"_angle", "0 0 0"},
                    {"_radius", "1"},
                    {"_fov", "45"}};
  const Items orth{{"_mode", "orth"}, {"_focus", "0 0 0"}, {"_angle", "10 0 0"}, {"_radius", "9"}};
  auto scene = importVox(file(frontMarked() + idDict("rCAM", 0, saved) + idDict("rCAM", 1, unset) +
                              idDict("rCAM", 2, unset) + idDict("rCAM", 3, orth)),
                         {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  ASSERT_EQ(scene->cameras.size(), 8u);
  const Camera& c = scene->cameras[7];
  EXPECT_EQ(c.name, "file_0");
  EXPECT_TRUE(cameraUsable(c));
  EXPECT_GT(c.position.z, c.target.z);  // in front (MagicaVoxel -Y) and above
  EXPECT_GT(c.position.y, c.target.y);
  EXPECT_NEAR(glm::length(c.position - c.target), 40.0 / 16, 1e-9);
  const std::string dropped = lines(report.dropped);
  EXPECT_TRUE(contains(dropped, "2 cameras (rCAM 1, 2) not imported: left at MagicaVoxel's"))
      << dropped;
  EXPECT_TRUE(contains(dropped, "camera rCAM 3 not imported: projection 'orth'")) << dropped;
}

// --- frames ---

TEST(VoxFrames, PackModelsAreFramesNotOverlaid) {
  const std::string two =
      pack(2) + model({1, 1, 1}, {{0, 0, 0, 1}}) + model({3, 1, 1}, {{0, 0, 0, 2}, {2, 0, 0, 2}});
  VoxImportReport report;
  auto first = importVox(file(two), {}, &report);
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_EQ(report.frames, 2);
  EXPECT_EQ(report.voxels, 1u);
  VoxImportOptions o;
  o.frame = 1;
  auto second = importVox(file(two), o, &report);
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_EQ(report.voxels, 2u);
  EXPECT_EQ(report.frame, 1);
  o.frame = 2;
  auto beyond = importVox(file(two), o);
  ASSERT_FALSE(beyond.ok());
  EXPECT_TRUE(contains(beyond.error(), "2 animation frames (0..1)")) << beyond.error();
}

// T0 -> S1: a transform keyed at frames 0 and 4, a shape with model 0 from frame 0 and model 1
// from frame 2.
std::string animated() {
  return model({1, 1, 1}, {{0, 0, 0, 1}}) + model({2, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 1}}) +
         transform(0, 1, -1, {{{"_f", "0"}}, {{"_f", "4"}, {"_t", "0 0 9"}}}) +
         shape(1, {{0, {{"_f", "0"}}}, {1, {{"_f", "2"}}}});
}

TEST(VoxFrames, KeyframesOfTransformsAndShapesPickTheFrame) {
  VoxImportReport report;
  VoxImportOptions o;
  for (int frame : {0, 2, 4}) {
    o.frame = frame;
    auto scene = importVox(file(animated()), o, &report);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_EQ(report.frames, 5);
    EXPECT_EQ(report.voxels, frame == 0 ? 1u : 2u) << frame;
  }
  o.frame = 5;
  auto beyond = importVox(file(animated()), o);
  ASSERT_FALSE(beyond.ok());
  EXPECT_TRUE(contains(beyond.error(), "5 animation frames")) << beyond.error();
}

TEST(VoxFrames, AbsurdFrameIndicesAndCountsAreRefused) {
  auto big = importVox(file(model({1, 1, 1}, {{0, 0, 0, 1}}) +
                            transform(0, 1, -1, {{{"_f", "99999999"}}}) + shape(1, {{0, {}}})));
  ASSERT_FALSE(big.ok());
  EXPECT_TRUE(contains(big.error(), "nTRN")) << big.error();
  EXPECT_TRUE(contains(big.error(), "byte")) << big.error();
  std::string c;
  put32(c, 0);
  c += dict({});
  for (int32_t v : {1, -1, -1, 2000000000}) put32(c, v);
  auto count = importVox(file(model({1, 1, 1}, {{0, 0, 0, 1}}) + chunk("nTRN", c)));
  ASSERT_FALSE(count.ok());
  EXPECT_TRUE(contains(count.error(), "frame count 2000000000 past the chunk")) << count.error();
  for (int32_t n : {-3, 0, 1 << 30}) {
    auto p = importVox(file(pack(n) + model({1, 1, 1}, {{0, 0, 0, 1}})));
    ASSERT_FALSE(p.ok()) << n;
    EXPECT_TRUE(contains(p.error(), "chunk 'PACK'")) << p.error();
  }
}

// --- layers ---

std::string layered() {
  return model({1, 1, 1}, {{0, 0, 0, 1}}) + model({1, 1, 1}, {{0, 0, 0, 2}}) +
         transform(0, 1, -1, {{}}) + group(1, {2, 4}) + transform(2, 3, 0, {{}}) +
         shape(3, {{0, {}}}) + transform(4, 5, 1, {{{"_t", "5 0 0"}}}) + shape(5, {{1, {}}}) +
         idDict("LAYR", 0, {{"_name", "walls"}}) +
         idDict("LAYR", 1, {{"_name", "roof"}, {"_hidden", "1"}});
}

TEST(VoxLayers, NamedHiddenLayersAreIncludedUnknownOnesListed) {
  VoxImportReport report;
  auto plain = importVox(file(layered()), {}, &report);
  ASSERT_TRUE(plain.ok()) << plain.error();
  EXPECT_EQ(report.instances, 1);
  for (const char* name : {"roof", "1"}) {
    VoxImportOptions o;
    o.layers = {name};
    auto both = importVox(file(layered()), o, &report);
    ASSERT_TRUE(both.ok()) << both.error();
    EXPECT_EQ(report.instances, 2) << name;
  }
  VoxImportOptions o;
  o.layers = {"attic"};
  auto unknown = importVox(file(layered()), o);
  ASSERT_FALSE(unknown.ok());
  EXPECT_TRUE(contains(unknown.error(),
                       "no layer 'attic'; its layers: 0 'walls', 1 'roof' "
                       "(hidden)"))
      << unknown.error();
}

// --- light ---

TEST(VoxLights, TheFilesSunAndSkyReplaceTheDefaults) {
  VoxImportReport report;
  auto plain = importVox(file(frontMarked()), {}, &report);
  ASSERT_TRUE(plain.ok()) << plain.error();
  EXPECT_TRUE(contains(lines(report.lights), "sun: the import's default")) << lines(report.lights);
  auto lit =
      importVox(file(frontMarked() +
                     chunk("rOBJ", dict({{"_type", "_inf"},
                                         {"_i", "1.2"},
                                         {"_k", "255 0 255"},
                                         {"_angle", "90 0"},
                                         {"_area", "0.1"}})) +
                     chunk("rOBJ", dict({{"_type", "_uni"}, {"_i", "0.5"}, {"_k", "255 255 0"}})) +
                     chunk("rOBJ", dict({{"_type", "_fog_uni"}, {"_d", "0"}}))),
                {}, &report);
  ASSERT_TRUE(lit.ok()) << lit.error();
  EXPECT_GT(glm::normalize(lit->sun->direction).y, 0.999);
  EXPECT_NEAR(lit->sun->irradiance.r, 6.0, 1e-9);
  EXPECT_NEAR(lit->sun->irradiance.g, 0.0, 1e-9);
  EXPECT_NEAR(lit->sun->angular_radius_deg, 4.5, 1e-9);
  EXPECT_NEAR(lit->sky.zenith.b, 0.0, 1e-9);
  EXPECT_NEAR(lit->sky.horizon.r, 0.5, 1e-9);
  EXPECT_TRUE(contains(lines(report.lights), "sun: from rOBJ _inf")) << lines(report.lights);
  EXPECT_TRUE(contains(lines(report.dropped), "_fog_uni")) << lines(report.dropped);
}

TEST(VoxLights, PerMaterialFluxSetsTheEmissionLevels) {
  VoxImportReport report;
  auto scene =
      importVox(file(model({3, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 2}, {2, 0, 0, 3}}) +
                     idDict("MATL", 1, {{"_type", "_emit"}, {"_emit", "1"}, {"_flux", "2"}}) +
                     idDict("MATL", 2, {{"_type", "_emit"}, {"_emit", "1"}, {"_flux", "1"}}) +
                     idDict("MATL", 3, {{"_type", "_emit"}, {"_emit", "1"}, {"_flux", "-3"}})),
                {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->palette[0].emission, 3);
  EXPECT_EQ(scene->palette[1].emission, 2);  // 3 x 1/2 rounds to 2
  EXPECT_EQ(scene->palette[2].emission, 1);  // 3 x 1/32: at least 1
  EXPECT_DOUBLE_EQ(scene->emission_scale, 16.0);
  EXPECT_TRUE(contains(lines(report.dropped), "per-material _flux (approximate)"));
}

// --- ground ---

TEST(VoxGround, AFloorUnderTheFootprintWithAMargin) {
  VoxImportOptions o;
  o.ground = true;
  VoxImportReport report;
  auto scene = importVox(file(frontMarked()), o, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  const int side = 4 + 2 * kGroundMargin;
  EXPECT_EQ(report.ground_voxels, uint64_t(side * side));
  VoxelWorld w = buildWorld(*scene);
  // The model's lowest voxels sit on y = 1, the floor at y = 0.
  EXPECT_NE(w.voxelAt({0, 0, 0}), 0);
  EXPECT_NE(w.voxelAt({side - 1, 0, side - 1}), 0);
  EXPECT_EQ(w.voxelAt({0, 1, 0}), 0);
  EXPECT_NE(w.voxelAt({kGroundMargin, 1, kGroundMargin}), 0);
  EXPECT_EQ(scene->palette.back().color, (std::array<int, 3>{200, 200, 200}));
}

// --- malformed new chunks ---

TEST(VoxBadInput, TruncatedAndNegativeNewChunksNameChunkAndOffset) {
  const std::string base = model({1, 1, 1}, {{0, 0, 0, 1}});
  std::string negative;
  put32(negative, 0);
  put32(negative, -5);  // dictionary size
  for (const auto& [bad, id] : std::vector<std::pair<std::string, std::string>>{
           {chunk("PACK", "ab"), "PACK"},
           {chunk("rCAM", negative), "rCAM"},
           {chunk("LAYR", negative), "LAYR"},
           {chunk("rOBJ", std::string("\xff\xff\xff\xff", 4)), "rOBJ"},
           {chunk("rLIT", dict({{"_i", "1"}}).substr(0, 9)), "rLIT"},
           {chunk("rAIR", std::string(3, '\0')), "rAIR"},
           {shape(0, {{0, {{"_f", "x"}}}}).substr(0, 30), "nSHP"}}) {
    std::string content = bad;
    if (id == "nSHP") {  // cut inside the chunk: fix its size to what is left
      const int32_t n = int32_t(content.size() - 12);
      std::memcpy(content.data() + 4, &n, 4);
    }
    auto r = importVox(file(base + content));
    ASSERT_FALSE(r.ok()) << id;
    EXPECT_TRUE(contains(r.error(), "chunk '" + id + "'")) << r.error();
    EXPECT_TRUE(contains(r.error(), ".vox byte ")) << r.error();
  }
}

TEST(VoxCli, FrameLayersAndGroundFlags) {
  const std::string dir = tempDir("vox_features");
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(writeFileAtomic(dir + "/a.vox", file(animated())).ok());
  CliResult r = runRdm("import " + dir + "/a.vox -o " + dir + "/a.json --frame 2 --ground");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* part :
       {"imported 2 models, 1 placed shape from the scene graph", "1 colour ",
        "frames:   5 animation frames; imported frame 2 (--frame to choose)",
        "ground:   ", "camera:   0 'default'", "light:    sun: the import's default"})
    EXPECT_TRUE(contains(r.out, part)) << part << "\n" << r.out;
  CliResult beyond = runRdm("import " + dir + "/a.vox -o " + dir + "/b.json --frame 7");
  EXPECT_NE(beyond.code, 0);
  EXPECT_TRUE(contains(beyond.err, "5 animation frames")) << beyond.err;
  ASSERT_TRUE(writeFileAtomic(dir + "/l.vox", file(layered())).ok());
  CliResult layers = runRdm("import " + dir + "/l.vox -o " + dir + "/l.json --layers walls,roof");
  ASSERT_EQ(layers.code, 0) << layers.err;
  EXPECT_TRUE(contains(layers.out, "2 placed shapes")) << layers.out;
}

}  // namespace
}  // namespace rdm
