// MagicaVoxel import: a model built byte by byte, and malformed files refused cleanly.
#include <gtest/gtest.h>

#include <cmath>

#include <cstring>
#include <filesystem>
#include <tuple>

#include "cli_run.h"
#include "rdm/bake/bake.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/vox_import.h"
#include "rdm/scene/world.h"
#include "vox_bytes.h"

namespace rdm {
namespace {

using test::chunk;
using test::dict;
using test::model;
using test::put32;
using test::str;

// A 20 x 3 x 2 model (MagicaVoxel z up) with voxels at its corners.
std::string makeVox() {
  std::string size;
  for (uint32_t v : {20u, 3u, 2u}) put32(size, v);
  std::string xyzi;
  put32(xyzi, 3);
  for (auto v : {std::array<uint8_t, 4>{0, 0, 0, 5}, {19, 2, 1, 7}, {17, 0, 1, 5}})
    xyzi.append(reinterpret_cast<const char*>(v.data()), 4);
  std::string rgba(1024, '\0');
  rgba[4 * 4] = char(200);      // colour index 5 -> red 200
  rgba[6 * 4 + 1] = char(100);  // colour index 7 -> green 100
  std::string children = chunk("SIZE", size) + chunk("XYZI", xyzi) + chunk("RGBA", rgba);
  std::string main = "MAIN";
  put32(main, 0);
  put32(main, uint32_t(children.size()));
  std::string file = "VOX ";
  put32(file, 150);
  return file + main + children;
}

TEST(VoxImport, ModelBecomesBlocksWithYUp) {
  auto scene = importVox(makeVox());
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->size, (std::array<int, 3>{2, 1, 1}));  // 20 x 2 (up) x 3 voxels
  EXPECT_EQ(scene->palette.size(), 2u);
  EXPECT_EQ(scene->palette[0].color[0], 200);
  EXPECT_EQ(scene->palette[1].color[1], 100);
  VoxelWorld w = buildWorld(*scene);
  EXPECT_NE(w.voxelAt({0, 0, 2}), 0);   // vox (0,0,0) -> (0, 0, 3-1-0)
  EXPECT_NE(w.voxelAt({19, 1, 0}), 0);  // vox (19,2,1) -> (19, 1, 0)
  EXPECT_NE(w.voxelAt({17, 1, 2}), 0);
  EXPECT_EQ(w.voxelAt({1, 0, 2}), 0);
}

TEST(VoxImport, MalformedFilesAreRefusedWithOffsets) {
  std::string good = makeVox();
  EXPECT_FALSE(importVox("").ok());
  EXPECT_NE(importVox("PNG!....").error().find("magic"), std::string::npos);
  for (size_t cut : {10ul, 20ul, 30ul, 50ul, good.size() - 5}) {
    auto r = importVox(good.substr(0, cut));
    EXPECT_FALSE(r.ok()) << cut;
  }
  std::string bad = good;
  bad[bad.find("XYZI") + 12] = char(100);  // voxel count beyond the chunk
  auto r = importVox(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("byte"), std::string::npos);
}

// --- scene graph, default palette and materials ---

std::string transform(int id, int child, int layer,
                      const std::vector<std::pair<std::string, std::string>>& frame) {
  std::string c;
  put32(c, uint32_t(id));
  c += dict({});
  put32(c, uint32_t(child));
  put32(c, uint32_t(-1));
  put32(c, uint32_t(layer));
  put32(c, 1);
  return chunk("nTRN", c + dict(frame));
}

std::string group(int id, const std::vector<int>& children) {
  std::string c;
  put32(c, uint32_t(id));
  c += dict({});
  put32(c, uint32_t(children.size()));
  for (int child : children) put32(c, uint32_t(child));
  return chunk("nGRP", c);
}

std::string shape(int id, int model_id) {
  std::string c;
  put32(c, uint32_t(id));
  c += dict({});
  put32(c, 1);
  put32(c, uint32_t(model_id));
  return chunk("nSHP", c + dict({}));
}

std::string material(int id, const std::vector<std::pair<std::string, std::string>>& props) {
  std::string c;
  put32(c, uint32_t(id));
  return chunk("MATL", c + dict(props));
}

std::string file(const std::string& children) {
  std::string main = "MAIN";
  put32(main, 0);
  put32(main, uint32_t(children.size()));
  std::string f = "VOX ";
  put32(f, 150);
  return f + main + children;
}

std::string palette() {
  std::string rgba(1024, '\0');
  for (int i = 0; i < 255; ++i) {
    rgba[size_t(4 * i)] = char(i + 1);  // colour index i + 1 -> red i + 1
    rgba[size_t(4 * i + 3)] = char(255);
  }
  return chunk("RGBA", rgba);
}

TEST(VoxImport, DefaultPaletteWithoutAnRgbaChunk) {
  VoxImportReport report;
  auto scene = importVox(
      file(model({4, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 36}, {2, 0, 0, 216}, {3, 0, 0, 255}})), {},
      &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_TRUE(report.default_palette);
  ASSERT_EQ(scene->palette.size(), 4u);
  // Entries of the table in MagicaVoxel's format description.
  EXPECT_EQ(scene->palette[0].color, (std::array<int, 3>{255, 255, 255}));          // 0xffffffff
  EXPECT_EQ(scene->palette[1].color, (std::array<int, 3>{255, 0, 0}));              // 0xff0000ff
  EXPECT_EQ(scene->palette[2].color, (std::array<int, 3>{238, 0, 0}));              // 0xff0000ee
  EXPECT_EQ(scene->palette[3].color, (std::array<int, 3>{17, 17, 17}));             // 0xff111111
  EXPECT_EQ(voxDefaultPalette()[2], (std::array<uint8_t, 4>{255, 255, 204, 255}));  // 0xffccffff
  EXPECT_EQ(voxDefaultPalette()[215], (std::array<uint8_t, 4>{0, 0, 51, 255}));     // 0xff330000
}

// Root T0 -> G1 -> {T2 -> S3 (model 0), T4 (rotated 90 degrees about z, moved +10 x) -> S5
// (model 1)}. Expected voxels: floor(R (v + 1/2 - size/2) + t).
std::string graphScene(int second_layer, const std::string& extra) {
  return file(model({2, 2, 2}, {{0, 0, 0, 1}}) + model({3, 1, 1}, {{0, 0, 0, 2}, {2, 0, 0, 3}}) +
              transform(0, 1, -1, {}) + group(1, {2, 4}) + transform(2, 3, 0, {}) + shape(3, 0) +
              transform(4, 5, second_layer, {{"_r", "17"}, {"_t", "10 0 0"}}) + shape(5, 1) +
              palette() + extra);
}

// The default camera frames the model: its box's centre on the optical axis and every
// corner of the box inside the vertical field of view (the horizontal one is wider).
TEST(VoxImport, DefaultCameraFramesTheModel) {
  auto scene = importVox(makeVox());
  ASSERT_TRUE(scene.ok()) << scene.error();
  ASSERT_EQ(scene->cameras.size(), 7u);  // "default" and the six standard views
  const Camera& c = scene->cameras[0];
  const glm::dvec3 lo(0.0, 0.0, 0.0), hi(20.0 / 16, 2.0 / 16, 3.0 / 16);  // the voxels' box
  const glm::dvec3 forward = glm::normalize(c.target - c.position);
  EXPECT_LT(glm::length(c.target - (lo + hi) * 0.5), 1e-9);
  const double half_fov = glm::radians(c.fov_deg) * 0.5;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const double angle = std::acos(glm::dot(glm::normalize(corner - c.position), forward));
    EXPECT_LT(angle, half_fov) << "corner " << k;
    EXPECT_GT(angle, 0.3 * half_fov) << "corner " << k << ": the model should fill the frame";
  }
}

TEST(VoxImport, SceneGraphPlacesEveryModelWithItsRotationAndTranslation) {
  VoxImportReport report;
  auto scene = importVox(graphScene(0, ""), {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_TRUE(report.scene_graph);
  EXPECT_EQ(report.models, 2);
  EXPECT_EQ(report.instances, 2);
  EXPECT_EQ(report.voxels, 3u);
  // MagicaVoxel voxels (-1,-1,-1), (10,-1,0), (10,1,0); box from (-1,-1,-1), 12 x 3 x 2 (z up)
  // -> ours (x, z, 2 - y).
  VoxelWorld w = buildWorld(*scene);
  auto red = [&](glm::ivec3 p) {
    const int index = w.voxelAt(p);
    return index ? scene->palette[size_t(index - 1)].color[0] : 0;
  };
  EXPECT_EQ(red({0, 0, 2}), 1);
  EXPECT_EQ(red({11, 1, 2}), 2);  // model 1's voxel x = 0, rotated to -y
  EXPECT_EQ(red({11, 1, 0}), 3);  // its voxel x = 2, rotated to +y
  EXPECT_EQ(red({11, 1, 1}), 0);
}

TEST(VoxImport, HiddenLayersAreLeftOutAndReported) {
  std::string layer;
  put32(layer, 1);
  layer += dict({{"_hidden", "1"}});
  put32(layer, uint32_t(-1));
  VoxImportReport report;
  auto scene = importVox(graphScene(1, chunk("LAYR", layer)), {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(report.instances, 1);
  EXPECT_EQ(report.hidden, 1);
  ASSERT_FALSE(report.dropped.empty());
  EXPECT_NE(report.dropped[0].find("hidden"), std::string::npos) << report.dropped[0];
}

TEST(VoxImport, MaterialsMapToRoughnessMetallicAndEmission) {
  const std::string materials =
      material(1, {{"_type", "_metal"}, {"_rough", "0.3"}, {"_metal", "1.0"}}) +
      material(2, {{"_type", "_emit"}, {"_emit", "0.5"}, {"_flux", "2"}}) +
      material(3, {{"_type", "_glass"}, {"_rough", "0"}, {"_ior", "1.5"}}) +
      material(4, {{"_type", "_diffuse"}});
  VoxImportReport report;
  auto scene =
      importVox(file(model({4, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 2}, {2, 0, 0, 3}, {3, 0, 0, 4}}) +
                     palette() + materials),
                {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  ASSERT_EQ(scene->palette.size(), 4u);
  const auto& p = scene->palette;
  EXPECT_EQ(std::make_tuple(p[0].roughness, p[0].metallic, p[0].emission),
            std::make_tuple(2, 3, 0));
  EXPECT_EQ(std::make_tuple(p[1].roughness, p[1].metallic, p[1].emission),
            std::make_tuple(7, 0, 2));
  EXPECT_EQ(std::make_tuple(p[2].roughness, p[2].metallic, p[2].emission),
            std::make_tuple(0, 0, 0));
  EXPECT_EQ(p[2].transmission, 1.0);  // glass without _trans is clear
  EXPECT_EQ(p[2].ior, 1.5);
  EXPECT_EQ(std::make_tuple(p[3].roughness, p[3].metallic, p[3].emission),
            std::make_tuple(7, 0, 0));
  EXPECT_DOUBLE_EQ(scene->emission_scale, 16.0);  // 4 * 2^_flux
  EXPECT_EQ(report.mapped.size(), 3u);
  std::string dropped;
  for (const std::string& d : report.dropped) dropped += d + "\n";
  EXPECT_EQ(dropped.find("_glass"), std::string::npos) << dropped;  // glass is simulated
  EXPECT_EQ(dropped.find("_ior"), std::string::npos) << dropped;
}

TEST(VoxImport, GlassKeepsItsTransmissionAndIndex) {
  // MagicaVoxel writes _ior as the index less 1 and _ri as the index; _trans the fraction
  // that is transparent; media with a density are still dropped.
  const std::string materials =
      material(1, {{"_type", "_glass"}, {"_trans", "0.6"}, {"_ior", "0.3"}}) +
      material(2, {{"_type", "_glass"}, {"_ri", "1.7"}, {"_ior", "0.3"}}) +
      material(3, {{"_type", "_glass"}, {"_rough", "0.4"}, {"_d", "0.2"}, {"_media", "1"}});
  VoxImportReport report;
  auto scene = importVox(
      file(model({3, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 2}, {2, 0, 0, 3}}) + palette() + materials),
      {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  const auto& p = scene->palette;
  EXPECT_DOUBLE_EQ(p[0].transmission, 0.6);
  EXPECT_DOUBLE_EQ(p[0].ior, 1.3);
  EXPECT_DOUBLE_EQ(p[1].ior, 1.7);
  EXPECT_DOUBLE_EQ(p[2].transmission, 1.0);
  std::string dropped;
  for (const std::string& d : report.dropped) dropped += d + "\n";
  EXPECT_NE(dropped.find("participating media"), std::string::npos) << dropped;
  EXPECT_NE(dropped.find("_rough on glass"), std::string::npos) << dropped;
}

// --- defaults chosen from the content ---

std::string chosen(const VoxImportReport& report) {
  std::string all;
  for (const std::string& line : report.chosen) all += line + "\n";
  return all;
}

// Atlas texels of every RDM and paths per sample (per face: the radiance map of a glossy
// block, the 2 x 2 level-7 RDM of a diffuse one), from the bake's own RDM list.
std::pair<uint64_t, uint64_t> texelsAndTraced(const Scene& scene) {
  const VoxelWorld world = buildWorld(scene);
  uint64_t texels = 0, traced = 0;
  for (const RdmId& id : listRdms(world, scene.bake)) {
    texels += 6 * uint64_t(id.size) * uint64_t(id.size);
    const int map_level = radianceMapLevel(world, scene.bake, id.slot);
    if (id.level == (map_level >= 0 ? map_level : 7)) traced += 6 * uint64_t(id.size * id.size);
  }
  return {texels, traced};
}

TEST(VoxImport, PlainDiffuseGetsLevelSevenOnlyAndTheSpecsSettings) {
  VoxImportReport report;
  auto scene = importVox(makeVox(), {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  for (const PaletteEntry& e : scene->palette) EXPECT_EQ(e.roughness, 7);
  EXPECT_EQ(listRdms(buildWorld(*scene), scene->bake).size(), 2u);  // one per block
  EXPECT_EQ(scene->bake.max_hemisphere, 256);
  EXPECT_EQ(scene->bake.spp, 256);
  EXPECT_EQ(scene->face_light_spp, 0);
  ASSERT_EQ(report.chosen.size(), 4u) << chosen(report);
  EXPECT_EQ(report.chosen[0],
            "roughness: level 7 for 2 diffuse colours (default: Lambert, no "
            "glossy RDM)");
  EXPECT_TRUE(contains(report.chosen[1], "no glossy block")) << chosen(report);
  EXPECT_TRUE(contains(report.chosen[3], "face light: off")) << chosen(report);
  // An explicit level still applies to every plain colour.
  VoxImportOptions glossy;
  glossy.roughness = 5;
  auto five = importVox(makeVox(), glossy, &report);
  ASSERT_TRUE(five.ok()) << five.error();
  for (const PaletteEntry& e : five->palette) EXPECT_EQ(e.roughness, 5);
  EXPECT_EQ(listRdms(buildWorld(*five), five->bake).size(), 4u);
  EXPECT_TRUE(contains(report.chosen[0], "level 5 for 2 diffuse colours (--roughness 5)"))
      << chosen(report);
}

// Sixteen blocks with a mirror-smooth glass voxel each: at S <= 256 their level-0 RDMs would
// hold 6.3M texels, over the 2^22 budget; at 128, 1.6M. Then 16 spp: 32 would trace 50M paths,
// over the 2^25 budget.
TEST(VoxImport, ManyGlossyBlocksGetSmallerMapsAndFewerSamples) {
  std::vector<std::array<uint8_t, 4>> voxels;
  for (uint8_t x = 0; x < 16; ++x) voxels.push_back({uint8_t(16 * x), 0, 0, 1});
  VoxImportReport report;
  auto scene =
      importVox(file(model({256, 1, 1}, voxels) + palette() + material(1, {{"_type", "_glass"}})),
                {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->palette[0].roughness, 0);
  EXPECT_EQ(scene->bake.max_hemisphere, 128) << chosen(report);
  EXPECT_EQ(scene->bake.spp, 16) << chosen(report);
  const auto [texels, traced] = texelsAndTraced(*scene);
  EXPECT_LE(texels, uint64_t(1) << 22);
  EXPECT_LE(traced * uint64_t(scene->bake.spp), uint64_t(1) << 25);
  EXPECT_EQ(report.chosen[0], "roughness: level 0 for 1 glass colour (from MATL)");
  EXPECT_TRUE(contains(report.chosen[1], "hemisphere: max 128 (16 of 16 blocks glossy"))
      << chosen(report);
  // Two such blocks fit at 256 (786k texels); 32 spp traces 25M paths, 64 would trace 50M.
  voxels.resize(2);
  auto two =
      importVox(file(model({256, 1, 1}, voxels) + palette() + material(1, {{"_type", "_glass"}})),
                {}, &report);
  ASSERT_TRUE(two.ok()) << two.error();
  EXPECT_EQ(two->bake.max_hemisphere, 256) << chosen(report);
  EXPECT_EQ(two->bake.spp, 32) << chosen(report);
  const auto [two_texels, two_traced] = texelsAndTraced(*two);
  EXPECT_LE(two_traced * 32, uint64_t(1) << 25);
  EXPECT_GT(two_traced * 64, uint64_t(1) << 25);
}

// Emitters turn the face light on; its spp keeps exposed faces x spp within 2^22 paths.
TEST(VoxImport, EmittersTurnTheFaceLightOn) {
  VoxImportReport report;
  auto scene = importVox(file(model({2, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 2}}) + palette() +
                              material(2, {{"_type", "_emit"}, {"_emit", "1"}})),
                         {}, &report);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->face_light_spp, 64);  // 10 exposed faces: the most, 64
  EXPECT_TRUE(contains(report.chosen[3], "face light: 64 spp (1 emissive colour; 10 exposed"))
      << chosen(report);
  EXPECT_TRUE(contains(report.chosen[0], "level 7 for 1 emissive colour")) << chosen(report);
  // A solid 64^3 emitter: 6 x 64^2 = 24,576 exposed faces -> 2^22 / 24,576 = 170 -> 64; a
  // 256 x 256 x 2 slab: 2 x 65,536 + 4 x 512 faces -> 31.5 -> 16.
  std::vector<std::array<uint8_t, 4>> slab;
  for (int x = 0; x < 256; ++x)
    for (int y = 0; y < 256; ++y)
      for (uint8_t z = 0; z < 2; ++z) slab.push_back({uint8_t(x), uint8_t(y), z, 2});
  auto lit = importVox(file(model({256, 256, 2}, slab) + palette() +
                            material(2, {{"_type", "_emit"}, {"_emit", "1"}})),
                       {}, &report);
  ASSERT_TRUE(lit.ok()) << lit.error();
  EXPECT_EQ(lit->face_light_spp, 16) << chosen(report);
}

TEST(VoxImport, CliPrintsWhatWasMappedAndDropped) {
  const std::string dir = tempDir("vox");
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(writeFileAtomic(dir + "/m.vox",
                              graphScene(0, material(2, {{"_type", "_glass"}, {"_ior", "1.3"}})))
                  .ok());
  CliResult r = runRdm("import " + dir + "/m.vox -o " + dir + "/m.json");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* part :
       {"imported 2 models, 2 placed shapes", "scene graph", "mapped:   colour 2 _glass",
        "glass: transmission 1.00, ior 1.30", "chosen:   roughness: level 7 for 2 diffuse colours",
        "level 0 for 1 glass colour (from MATL)", "chosen:   hemisphere: max",
        "chosen:   spp: ", "chosen:   face light: off"})
    EXPECT_TRUE(contains(r.out, part)) << r.out;
  EXPECT_EQ(runRdm("bake " + dir + "/m.json --spp 1 --max-hemisphere 4 -q -o " + dir + "/out").code,
            0);
}

TEST(VoxImport, CyclesAndExplodingSharingAreRefused) {
  const std::string models = model({1, 1, 1}, {{0, 0, 0, 1}});
  auto cycle = importVox(
      file(models + transform(0, 1, -1, {}) + group(1, {2}) + transform(2, 1, -1, {}) + palette()));
  ASSERT_FALSE(cycle.ok());
  EXPECT_NE(cycle.error().find("ancestor"), std::string::npos) << cycle.error();
  // Each group lists the next one 16 times: 16^8 paths to one shape.
  std::string chain = transform(0, 1, -1, {});
  for (int g = 1; g <= 8; ++g) chain += group(g, std::vector<int>(16, g + 1));
  chain += transform(9, 10, -1, {}) + shape(10, 0);
  auto bomb = importVox(file(models + chain + palette()));
  ASSERT_FALSE(bomb.ok());
  EXPECT_NE(bomb.error().find("too large"), std::string::npos) << bomb.error();
}

}  // namespace
}  // namespace rdm
