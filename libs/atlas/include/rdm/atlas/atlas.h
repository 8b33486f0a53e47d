// Atlas layout (docs/spec.md section 4): the canonical packer, atlas page assembly, index.json
// and the thesis's index.txt.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rdm/bake/rdm_list.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/base/status.h"
#include "rdm/image/bc6h.h"
#include "rdm/image/image.h"
#include "rdm/scene/lighting_fingerprint.h"

namespace rdm {

constexpr int kMaxPageSize = 16384;  // lavapipe's maxImageDimension2D; the largest page read
// The largest page side packCanonical makes: Vulkan's guaranteed maxImageDimension2D, and
// 256 MiB of float R, G, B, Z, the most a writer holds at once (docs/spec.md section 4).
constexpr int kPackedPageSize = 4096;
// index.json version: 2 stores each face as its own tile; version 1 (one 2S x 3S rect per
// RDM) is refused with a message saying to bake again.
constexpr int kAtlasIndexVersion = 2;

struct AtlasPage {
  int width = 0, height = 0;
};

// Bit f set: face f of an RDM holds data. A face skipped by section 3's rule is not stored.
using FaceMask = uint8_t;
constexpr FaceMask kAllFaces = 0x3f;
// The stored faces of an RDM at `slot` (every level of a slot has the same mask).
using StoredFaces = std::function<FaceMask(const glm::ivec3& slot)>;
StoredFaces storedFacesOf(const VoxelWorld& world);           // keeps a reference to `world`
StoredFaces storedFacesOf(const std::vector<RdmData>& rdms);  // from RdmData::skipped
FaceMask allFaces(const glm::ivec3& slot);                    // every face stored

// How atlas pages store R, G, B: float32; half with a power-of-two scale per tile so that
// radiance above half's 65504 (sun-lit mirrors) stays finite; or BC6H unsigned float in KTX2
// files with the same per-tile scale (Z then goes to separate half EXRs; docs/bc6h.md).
enum class RadianceFormat { kFloat32, kHalf, kBc6h };
// Side of a BC6H block: in a bc6h layout every tile starts at a multiple of it and tiles with
// S below it take a whole block-sized cell (docs/spec.md section 4).
constexpr int kBc6hTileAlign = 4;
constexpr float kHalfMax = 65504.0f;
constexpr int kMaxTileExponent = 112;  // kHalfMax * 2^112 is about FLT_MAX

// One face's S x S texels at (x, y) of `page`; page -1: the face is not stored. The page
// holds the face's radiance times 2^-exponent (0 unless the atlas is half).
struct FaceTile {
  int page = -1;
  int x = 0, y = 0;
  int exponent = 0;
  bool stored() const { return page >= 0; }
  bool operator==(const FaceTile&) const = default;
};

struct AtlasEntry {
  RdmId id;
  std::array<FaceTile, 6> faces{};
  FaceMask storedMask() const;
};

struct AtlasLayout {
  std::vector<AtlasPage> pages;
  std::vector<AtlasEntry> entries;  // canonical order
  long long scene_version = 1;
  RadianceFormat radiance = RadianceFormat::kFloat32;
  LightingFingerprint lighting;  // of the scene baked; empty: unknown (written before 2026-12)
  double occupancy() const;
  size_t storedTiles() const;  // face tiles of every entry
  const AtlasEntry* find(const glm::ivec3& slot, int level) const;
};

// Every stored tile of `e` lies inside its page.
bool tilesFit(const AtlasEntry& e, const std::vector<AtlasPage>& pages);

// A pure function of the RDM list and their stored faces: sorts the face tiles canonically
// (RDM order, then face), packs rows of square power-of-two cells subdivided into quadrants,
// and picks the page width with the best occupancy. With `format` kBc6h every tile's cell is
// at least kBc6hTileAlign wide (float32 and half layouts do not depend on `format`); the
// result's `radiance` is `format`.
AtlasLayout packCanonical(std::vector<RdmId> rdms, const StoredFaces& stored,
                          RadianceFormat format = RadianceFormat::kFloat32);
// Every stored tile starts at multiples of kBc6hTileAlign, every page side is one, and no
// two tiles share a block.
bool blockAligned(const AtlasLayout& layout);

// Calls `use` for every RDM of `source` with a tile on page `page`, in layout order, with its
// entry; RDMs of the layout absent from `source` are left out. Reads one RDM at a time.
Status forEachRdmOnPage(const AtlasLayout& layout, int page, const RdmSource& source,
                        const std::function<void(const AtlasEntry&, const RdmData&)>& use);
// Page `page` of R, G, B, Z as stored (each tile's R, G, B times 2^-exponent); uncovered
// texels are 0.
Expected<Image> assembleAtlasPage(const AtlasLayout& layout, int page, const RdmSource& source);
// Every page at once, from RDMs in memory (2S x 3S images, in any order).
std::vector<Image> assembleAtlas(const AtlasLayout& layout, const std::vector<RdmData>& rdms);

// `layout` with the tile exponents its radiance format needs: for kHalf, each tile's is the
// smallest e >= 0 that brings its largest R, G or B to at most kHalfMax; for kFloat32, 0.
AtlasLayout withTileExponents(AtlasLayout layout, const std::vector<RdmDigest>& rdms);
// Multiplies R, G, B of the size x size tile `t` of `page` by 2^exponent.
void scaleTile(Image& page, const FaceTile& t, int size, int exponent);
// Undoes a page's stored scale in place, so `page` (read from the file) holds radiance.
void restoreRadiance(const AtlasLayout& layout, int page_index, Image& page);

std::string indexToJson(const AtlasLayout& layout);
Expected<AtlasLayout> parseIndexJson(const std::string& text);
std::string indexToText(const AtlasLayout& layout);  // page 0's tiles, one line each

// Writes atlas.exr (page 0; further pages atlas.page<N>.exr), index.json and index.txt into
// `dir`, each atomically, radiance in layout.radiance (tile exponents from
// withTileExponents). A bc6h atlas writes atlas.ktx2 and depth.exr per page instead
// (atlasKtx2FileName, atlasDepthFileName); its layout must be blockAligned, as
// packCanonical(..., RadianceFormat::kBc6h) makes it (RDM_CHECK). Fails with a message
// naming any non-finite texel, writing nothing.
// Assembles and writes one page at a time: it holds one page and one RDM besides `source`.
// `bc6h` encodes a bc6h atlas's pages (empty: encodeBc6h); every encoder gives the same blocks.
// `reuse` (bc6h only): the blocks an incremental atlas copies from its base.
struct Bc6hReuse;
Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& layout, const RdmSource& source,
                         const Bc6hEncodeFn& bc6h = {}, Bc6hReuse* reuse = nullptr);
Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& layout,
                         const std::vector<RdmData>& rdms, const Bc6hEncodeFn& bc6h = {});
// "float32", "half" or "bc6h".
Expected<RadianceFormat> parseRadianceFormat(const std::string& name);
const char* radianceFormatName(RadianceFormat format);
std::string atlasPageFileName(int page);   // atlas.exr, atlas.page<N>.exr
std::string atlasKtx2FileName(int page);   // bc6h: atlas.ktx2, atlas.page<N>.ktx2 (R, G, B)
std::string atlasDepthFileName(int page);  // bc6h: depth.exr, depth.page<N>.exr (Z, half)

// Page `page` of a bc6h atlas in `dir` as R, G, B, Z floats, as stored (tile exponents not
// undone), texels outside the layout's tiles 0. Errors name the file and what is wrong.
[[nodiscard]] Expected<Image> readBc6hAtlasPage(const std::string& dir, const AtlasLayout& layout,
                                                int page);
// The parts of readBc6hAtlasPage: the page's blocks as stored (the KTX2's format and size
// checked), and its Z (one channel).
[[nodiscard]] Expected<Bc6hImage> readBc6hAtlasBlocks(const std::string& dir,
                                                      const AtlasLayout& layout, int page);
[[nodiscard]] Expected<Image> readBc6hAtlasDepth(const std::string& dir, const AtlasLayout& layout,
                                                 int page);
// Page `page` as readBc6hAtlasPage gives it, from its blocks and Z (sizes checked).
[[nodiscard]] Expected<Image> joinBc6hAtlasPage(const AtlasLayout& layout, int page,
                                                const Bc6hImage& blocks, const Image& depth);
// Writes page `page` (R, G, B, Z as stored, from assembleAtlasPage) of a bc6h atlas into
// `dir`: its small tiles padded (padSmallTiles), R, G, B encoded to atlasKtx2FileName, Z to
// atlasDepthFileName as half, by `encode` (empty: encodeBc6h). Each file atomically.
[[nodiscard]] Status writeBc6hAtlasPage(const std::string& dir, const AtlasLayout& layout, int page,
                                        Image& texels, const Bc6hEncodeFn& encode = {},
                                        Bc6hReuse* reuse = nullptr);

// An incremental bc6h atlas's blocks that are not encoded again (docs/bc6h.md, "Incremental
// atlases"): every block of a face tile whose RDM `rebaked` does not name and that sits on the
// same page at the same place with the same scale exponent in `base` (a bc6h layout) is
// copied from the base's page, which `base_page` gives (blocks as stored). Blocks are encoded
// independently, so the page's bytes are those a whole encode gives when the base's blocks
// are that RDM's. The counts say what each write did.
struct Bc6hReuse {
  AtlasLayout base;
  std::function<Expected<Bc6hImage>(int page)> base_page;
  std::function<bool(const RdmId&)> rebaked;
  size_t encoded_blocks = 0, reused_blocks = 0;
};
// Encodes page `page` of `layout` from `texels` (padded as writeBc6hAtlasPage pads them),
// taking from `reuse`'s base what it may.
[[nodiscard]] Expected<Bc6hImage> encodeBc6hReusing(const AtlasLayout& layout, int page,
                                                    const Image& texels, const Bc6hEncodeFn& encode,
                                                    Bc6hReuse& reuse);
// Fills the kBc6hTileAlign cell of every tile of `page` smaller than it with copies of the
// tile's edge texels (R, G, B only), so each block's endpoints are that tile's own.
void padSmallTiles(const AtlasLayout& layout, int page, Image& texels);

// An atlas as `writeAtlasOutputs` wrote it: the layout and every page (R, G, B, Z), the
// stored scale undone.
struct LoadedAtlas {
  AtlasLayout layout;
  std::vector<Image> pages;
};
// index.json of the atlas output directory `dir`, parsed (readAtlasOutputs without the pages).
Expected<AtlasLayout> readAtlasLayout(const std::string& dir);
// Reads index.json and every page of `dir`, refusing pages whose size differs from the index.
Expected<LoadedAtlas> readAtlasOutputs(const std::string& dir);
// The 2S x 3S image of `entry`, its faces read from their tiles; unstored faces are 0.
Image rdmTexels(const LoadedAtlas& atlas, const AtlasEntry& entry);

// Face `face`'s S x S texels of a 2S x 3S RDM image.
Image faceTexels(const Image& rdm_image, int face);

// RDM by RDM, wherever each atlas placed them: the RDMs of `a` absent from `b` (by slot
// and level) or of another size or stored faces or with any texel not bit-identical, then those of
// `b` absent from `a`. Empty when both hold the same RDMs with the same texels.
std::vector<RdmId> differingRdms(const LoadedAtlas& a, const LoadedAtlas& b);

// An index belongs to a scene when it holds exactly the scene's RDMs by slot and level
// (listRdms; sizes may differ, since a bake may override max_hemisphere). Fails with
// kInvalidInput naming the first difference.
Status checkLayoutMatches(const AtlasLayout& layout, const std::vector<RdmId>& rdms);

}  // namespace rdm
