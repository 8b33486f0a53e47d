// The 24 block orientations of docs/spec.md section 1 (rot = 4a + b, R = T_a Ry(90 b)) against the
// shared known-answer table tests/data/rotations.json, and their use by buildWorld.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

using glm::ivec3;
using Matrix = std::array<std::array<int, 3>, 3>;  // rows

struct RotationCase {
  int rot = 0;
  Matrix rows{};
  ivec3 voxel_1_2_3_goes_to{0};
};

std::vector<RotationCase> loadRotations() {
  std::ifstream in(std::string(RDM_TEST_DATA_DIR) + "/rotations.json");
  EXPECT_TRUE(in.good()) << "cannot open rotations.json";
  nlohmann::json j = nlohmann::json::parse(in);
  std::vector<RotationCase> cases;
  for (const auto& entry : j.at("rotations")) {
    RotationCase c;
    c.rot = entry.at("rot").get<int>();
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) c.rows[r][col] = entry.at("matrix_rows")[r][col].get<int>();
    for (int a = 0; a < 3; ++a)
      c.voxel_1_2_3_goes_to[a] = entry.at("voxel_1_2_3_goes_to")[a].get<int>();
    cases.push_back(c);
  }
  return cases;
}

ivec3 mulVec(const Matrix& m, const ivec3& v) {
  ivec3 out;
  for (int r = 0; r < 3; ++r) out[r] = m[r][0] * v.x + m[r][1] * v.y + m[r][2] * v.z;
  return out;
}

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix out{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) out[r][c] += a[r][k] * b[k][c];
  return out;
}

int determinant(const Matrix& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Matrix of orientVector, read off its images of the unit vectors (columns).
Matrix matrixOf(int rot) {
  Matrix m{};
  for (int c = 0; c < 3; ++c) {
    ivec3 e(0);
    e[c] = 1;
    ivec3 column = shared::orientVector(rot, e);
    for (int r = 0; r < 3; ++r) m[r][c] = column[r];
  }
  return m;
}

// Right-handed rotations by quarter turns q (angle 90 q degrees), integer cos/sin.
int cosQ(int q) {
  return std::array<int, 4>{1, 0, -1, 0}[((q % 4) + 4) % 4];
}
int sinQ(int q) {
  return std::array<int, 4>{0, 1, 0, -1}[((q % 4) + 4) % 4];
}
// docs/spec.md section 1: Ry(t): (x, y, z) -> (x cos t + z sin t, y, -x sin t + z cos t).
Matrix rotY(int q) {
  return Matrix{{{cosQ(q), 0, sinQ(q)}, {0, 1, 0}, {-sinQ(q), 0, cosQ(q)}}};
}
Matrix rotX(int q) {
  return Matrix{{{1, 0, 0}, {0, cosQ(q), -sinQ(q)}, {0, sinQ(q), cosQ(q)}}};
}
Matrix rotZ(int q) {
  return Matrix{{{cosQ(q), -sinQ(q), 0}, {sinQ(q), cosQ(q), 0}, {0, 0, 1}}};
}

// T_a of docs/spec.md section 1, written from its prose.
Matrix specT(int a) {
  switch (a) {
    case 1:
      return rotX(2);  // 180 deg about X: +Y -> -Y
    case 2:
      return rotZ(-1);  // -90 deg about Z: +Y -> +X
    case 3:
      return rotZ(1);  // +90 deg about Z: +Y -> -X
    case 4:
      return rotX(1);  // +90 deg about X: +Y -> +Z
    case 5:
      return rotX(-1);  // -90 deg about X: +Y -> -Z
    default:
      return rotY(0);  // identity
  }
}

// Slot voxel of block-local voxel p under R, in doubled integer units about the centre:
// p_slot + 0.5 = R (p + 0.5 - 8) + 8.
ivec3 voxelUnder(const Matrix& r, const ivec3& p) {
  ivec3 q = mulVec(r, p * 2 - ivec3(15));
  return (q + ivec3(15)) / 2;
}

TEST(OrientationTest, TableHas24Entries) {
  auto cases = loadRotations();
  ASSERT_EQ(cases.size(), 24u);
  for (int i = 0; i < 24; ++i) EXPECT_EQ(cases[i].rot, i);
  EXPECT_EQ(shared::kOrientationCount, 24);
}

TEST(OrientationTest, TableMatchesSpecFormula) {
  // The known-answer table itself agrees with R = T_a Ry(90 b).
  for (const RotationCase& c : loadRotations()) {
    SCOPED_TRACE("rot " + std::to_string(c.rot));
    EXPECT_EQ(c.rows, multiply(specT(c.rot / 4), rotY(c.rot % 4)));
  }
}

TEST(OrientationTest, OrientVectorGivesMatrixColumns) {
  for (const RotationCase& c : loadRotations()) {
    SCOPED_TRACE("rot " + std::to_string(c.rot));
    for (int col = 0; col < 3; ++col) {
      ivec3 e(0);
      e[col] = 1;
      ivec3 expected(c.rows[0][col], c.rows[1][col], c.rows[2][col]);
      EXPECT_EQ(shared::orientVector(c.rot, e), expected) << "column " << col;
    }
    // Linear: an arbitrary vector maps through the same matrix.
    ivec3 v(3, -5, 7);
    EXPECT_EQ(shared::orientVector(c.rot, v), mulVec(c.rows, v));
  }
}

TEST(OrientationTest, OrientTransformAndRotateAboutYCompose) {
  for (int rot = 0; rot < 24; ++rot) {
    ivec3 v(2, 3, 5);
    EXPECT_EQ(shared::orientVector(rot, v),
              shared::orientTransform(rot / 4, shared::rotateAboutY(rot % 4, v)));
    EXPECT_EQ(shared::rotateAboutY(rot % 4, v), mulVec(rotY(rot % 4), v));
    EXPECT_EQ(shared::orientTransform(rot / 4, v), mulVec(specT(rot / 4), v));
  }
}

TEST(OrientationTest, Voxel123KnownAnswers) {
  for (const RotationCase& c : loadRotations()) {
    SCOPED_TRACE("rot " + std::to_string(c.rot));
    EXPECT_EQ(shared::orientVoxel(c.rot, ivec3(1, 2, 3)), c.voxel_1_2_3_goes_to);
    EXPECT_EQ(voxelUnder(c.rows, ivec3(1, 2, 3)), c.voxel_1_2_3_goes_to);
  }
}

TEST(OrientationTest, EveryOrientationIsABijectionOnVoxels) {
  for (const RotationCase& c : loadRotations()) {
    SCOPED_TRACE("rot " + std::to_string(c.rot));
    std::vector<bool> hit(4096, false);
    int mismatches = 0;
    for (int z = 0; z < 16; ++z)
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
          ivec3 p = shared::orientVoxel(c.rot, ivec3(x, y, z));
          ASSERT_TRUE(glm::all(glm::greaterThanEqual(p, ivec3(0))) &&
                      glm::all(glm::lessThan(p, ivec3(16))))
              << "voxel " << x << "," << y << "," << z << " leaves the block";
          int index = p.x + 16 * p.y + 256 * p.z;
          ASSERT_FALSE(hit[index]) << "two voxels land on index " << index;
          hit[index] = true;
          if (p != voxelUnder(c.rows, ivec3(x, y, z))) ++mismatches;
        }
    EXPECT_EQ(mismatches, 0) << "orientVoxel disagrees with R (p - c) + c";
  }
}

TEST(OrientationTest, UpAxisFollowsA) {
  const std::array<ivec3, 6> up_goes_to = {ivec3(0, 1, 0),  ivec3(0, -1, 0), ivec3(1, 0, 0),
                                           ivec3(-1, 0, 0), ivec3(0, 0, 1),  ivec3(0, 0, -1)};
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 4; ++b) {
      EXPECT_EQ(shared::orientVector(4 * a + b, ivec3(0, 1, 0)), up_goes_to[a])
          << "rot " << 4 * a + b;
    }
  // b turns about the block's own +Y first: for a = 0 the quarter turn takes +X to -Z.
  EXPECT_EQ(shared::orientVector(1, ivec3(1, 0, 0)), ivec3(0, 0, -1));
  EXPECT_EQ(shared::orientVector(1, ivec3(0, 0, 1)), ivec3(1, 0, 0));
}

TEST(OrientationTest, DeterminantsArePlusOneAndAllDistinct) {
  std::set<Matrix> seen;
  for (int rot = 0; rot < 24; ++rot) {
    Matrix m = matrixOf(rot);
    EXPECT_EQ(determinant(m), 1) << "rot " << rot;
    // Orthogonal: R R^T = I.
    Matrix transpose{};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) transpose[r][c] = m[c][r];
    EXPECT_EQ(multiply(m, transpose), rotY(0)) << "rot " << rot;
    seen.insert(m);
  }
  EXPECT_EQ(seen.size(), 24u);
}

// ---- OrientedBlock: buildWorld rotates voxels into slot space --------------------------

Scene singleVoxelScene() {
  Scene s;
  s.size = {24, 1, 1};
  s.palette = {{{255, 255, 255}, 3, 0, 0}};
  Block dot;
  dot.voxels[1 + 16 * 2 + 256 * 3] = 1;
  s.blocks["dot"] = dot;
  for (int rot = 0; rot < 24; ++rot) s.placements.push_back({{rot, 0, 0}, "dot", rot});
  return s;
}

TEST(OrientationTest, OrientedBlockPutsVoxelAtRotatedPosition) {
  Scene scene = singleVoxelScene();
  ASSERT_TRUE(validateScene(scene).ok());
  VoxelWorld world = buildWorld(scene);
  ASSERT_EQ(world.blocks.size(), 24u);
  for (const RotationCase& c : loadRotations()) {
    SCOPED_TRACE("rot " + std::to_string(c.rot));
    int32_t b = world.blockAt(ivec3(c.rot, 0, 0));
    ASSERT_GE(b, 0);
    const OrientedBlock& block = world.blocks[b];
    EXPECT_EQ(block.rot, c.rot);
    EXPECT_EQ(block.name, "dot");
    EXPECT_EQ(block.solid_count, 1);
    EXPECT_EQ(block.level_mask, 1u << 3);
    ivec3 p = c.voxel_1_2_3_goes_to;
    int index = p.x + 16 * p.y + 256 * p.z;
    for (int v = 0; v < 4096; ++v) EXPECT_EQ(block.voxels[v], v == index ? 1 : 0) << "voxel " << v;
    // The global voxel lookup sees it in its slot, and nothing at the unrotated position
    // unless the rotation fixes it.
    ivec3 global = ivec3(c.rot * 16, 0, 0) + p;
    EXPECT_EQ(world.voxelAt(global), 1);
    if (p != ivec3(1, 2, 3)) {
      EXPECT_EQ(world.voxelAt(ivec3(c.rot * 16, 0, 0) + ivec3(1, 2, 3)), 0);
    }
  }
}

TEST(OrientationTest, SameBlockAndRotationShareOneOrientedBlock) {
  Scene scene = singleVoxelScene();
  scene.size = {24, 2, 1};
  scene.placements.push_back({{0, 1, 0}, "dot", 5});
  scene.placements.push_back({{1, 1, 0}, "dot", 5});
  VoxelWorld world = buildWorld(scene);
  EXPECT_EQ(world.blocks.size(), 24u);
  EXPECT_EQ(world.blockAt(ivec3(0, 1, 0)), world.blockAt(ivec3(5, 0, 0)));
  EXPECT_EQ(world.blockAt(ivec3(1, 1, 0)), world.blockAt(ivec3(5, 0, 0)));
}

// Face whose outward normal is n (docs/spec.md face order 0 +X, 1 -X, 2 +Y, 3 -Y, 4 +Z, 5 -Z).
int faceOf(const ivec3& n) {
  for (int f = 0; f < 6; ++f) {
    if (shared::faceNormal(f) == n) return f;
  }
  return -1;
}

TEST(OrientationTest, FaceFullForHalfFilledBlock) {
  // Bottom half (local y < 8) solid: only the layer against local -Y is full; after
  // rotation that is the face with normal R (0, -1, 0).
  Scene scene;
  scene.size = {24, 1, 1};
  scene.palette = {{{128, 128, 128}, 7, 0, 0}};
  Block half;
  for (int v = 0; v < 4096; ++v) half.voxels[v] = (v / 16) % 16 < 8 ? 1 : 0;
  scene.blocks["half"] = half;
  for (int rot = 0; rot < 24; ++rot) scene.placements.push_back({{rot, 0, 0}, "half", rot});
  VoxelWorld world = buildWorld(scene);
  const std::map<int, int> spot_checks = {{0, 3},  {4, 2},  {8, 1}, {12, 0},
                                          {16, 5}, {20, 4}, {9, 1}};
  for (int rot = 0; rot < 24; ++rot) {
    SCOPED_TRACE("rot " + std::to_string(rot));
    const OrientedBlock& block = world.blocks[world.blockAt(ivec3(rot, 0, 0))];
    EXPECT_EQ(block.solid_count, 2048);
    int full = faceOf(shared::orientVector(rot, ivec3(0, -1, 0)));
    ASSERT_GE(full, 0);
    if (spot_checks.count(rot)) {
      EXPECT_EQ(full, spot_checks.at(rot));
    }
    for (int f = 0; f < 6; ++f) EXPECT_EQ(block.face_full[f], f == full) << "face " << f;
  }
}

TEST(OrientationTest, FaceFullForSolidAndNotchedBlocks) {
  Scene scene;
  scene.size = {3, 1, 1};
  scene.palette = {{{128, 128, 128}, 7, 0, 0}};
  Block solid;
  solid.voxels.assign(4096, 1);
  Block notched = solid;
  notched.voxels[15 + 16 * 0 + 256 * 0] = 0;  // corner (15, 0, 0): on the +X, -Y and -Z layers
  scene.blocks["solid"] = solid;
  scene.blocks["notched"] = notched;
  scene.placements = {
      {{0, 0, 0}, "solid", 7}, {{1, 0, 0}, "notched", 0}, {{2, 0, 0}, "notched", 2}};
  VoxelWorld world = buildWorld(scene);
  const OrientedBlock& s = world.blocks[world.blockAt(ivec3(0, 0, 0))];
  for (int f = 0; f < 6; ++f) EXPECT_TRUE(s.face_full[f]) << "face " << f;
  const OrientedBlock& n0 = world.blocks[world.blockAt(ivec3(1, 0, 0))];
  EXPECT_EQ(n0.face_full, (std::array<bool, 6>{false, true, true, false, true, false}));
  // rot 2 (half turn about Y): corner (15, 0, 0) goes to (0, 0, 15): -X, -Y, +Z layers.
  const OrientedBlock& n2 = world.blocks[world.blockAt(ivec3(2, 0, 0))];
  EXPECT_EQ(n2.voxels[0 + 16 * 0 + 256 * 15], 0);
  EXPECT_EQ(n2.face_full, (std::array<bool, 6>{true, false, true, false, false, true}));
}

}  // namespace
}  // namespace rdm
