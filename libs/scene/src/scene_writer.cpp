// The scene document writer (docs/spec.md section 2): sceneToJson and saveSceneFile. The
// placements, which can number millions, are written one line each without a JSON DOM and
// streamed to disk in pieces, so saving a scene costs little beyond the scene itself.
#include <charconv>
#include <map>
#include <string_view>

#include <nlohmann/json.hpp>

#include "rdm/base/base64.h"
#include "rdm/base/check.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/bake_settings_json.h"
#include "rdm/scene/scene.h"

namespace rdm {
namespace {

using nlohmann::json;

constexpr size_t kPieceBytes = 1u << 16;  // what a streamed write hands over at a time

json vec3Json(const glm::dvec3& v) {
  return json::array({v.x, v.y, v.z});
}

json blockJson(const Block& block) {
  bool uniform = true;
  for (uint8_t v : block.voxels) uniform = uniform && v == block.voxels[0];
  if (uniform) return json{{"fill", block.voxels[0]}};
  return json{{"voxels", base64Encode(block.voxels)}};
}

// Every field but the placements, as a DOM with an empty placements array.
json sceneWithoutPlacements(const Scene& s) {
  json j;
  j["format"] = "rdm-scene";
  j["version"] = 1;
  j["size"] = s.size;
  j["palette"] = json::array();
  for (const PaletteEntry& e : s.palette) {
    json entry = {{"color", e.color},
                  {"roughness", e.roughness},
                  {"metallic", e.metallic},
                  {"emission", e.emission}};
    if (e.transmission > 0.0) entry.update({{"transmission", e.transmission}, {"ior", e.ior}});
    j["palette"].push_back(std::move(entry));
  }
  j["blocks"] = json::object();
  for (const auto& [name, block] : s.blocks) j["blocks"][name] = blockJson(block);
  j["placements"] = json::array();
  if (s.sun) {
    j["sun"] = {{"direction", vec3Json(s.sun->direction)},
                {"irradiance", vec3Json(s.sun->irradiance)},
                {"angular_radius_deg", s.sun->angular_radius_deg}};
  }
  j["sky"] = {{"zenith", vec3Json(s.sky.zenith)},
              {"horizon", vec3Json(s.sky.horizon)},
              {"ground", vec3Json(s.sky.ground)}};
  j["emission_scale"] = s.emission_scale;
  j["ambient"] = vec3Json(s.ambient);
  j["bake"] = bakeSettingsToJson(s.bake);
  if (s.face_light_spp > 0) j["bake"]["face_light_spp"] = s.face_light_spp;
  j["cameras"] = json::array();
  for (const Camera& c : s.cameras) {
    json camera = {
        {"position", vec3Json(c.position)}, {"target", vec3Json(c.target)}, {"fov_deg", c.fov_deg}};
    if (!c.name.empty()) camera["name"] = c.name;
    j["cameras"].push_back(std::move(camera));
  }
  return j;
}

// One placement's line, `  {"at": [x, y, z], "block": NAME, "rot": r}`, where NAME is the
// block name as a JSON string.
constexpr std::string_view kAtOpen = "  {\"at\": [", kComma = ", ",
                           kBlock = "], \"block\": ", kRot = ", \"rot\": ", kClose = "}",
                           kNext = ",\n";

void appendDecimal(std::string& out, int v) {
  char buf[12];
  out.append(buf, size_t(std::to_chars(buf, buf + sizeof buf, v).ptr - buf));
}

class SceneJsonWriter {
 public:
  explicit SceneJsonWriter(const Scene& s) : scene_(s), doc_(sceneWithoutPlacements(s).dump(1)) {
    const std::string marker = "\n \"placements\": []";
    const size_t at = doc_.find(marker);
    RDM_CHECK(at != std::string::npos);
    open_end_ = at + marker.size() - 1;  // just after '['
    for (const Placement& p : s.placements) {
      if (!quoted_.count(p.block)) quoted_[p.block] = json(p.block).dump();
    }
  }

  // Calls `sink` with consecutive pieces of the document, each at most about kPieceBytes.
  template <typename Sink>
  void write(Sink&& sink) const {
    if (scene_.placements.empty()) {
      sink(std::string_view(doc_));
      sink(std::string_view("\n"));
      return;
    }
    std::string piece(doc_, 0, open_end_);
    piece += "\n";
    for (size_t i = 0; i < scene_.placements.size(); ++i) {
      appendLine(piece, scene_.placements[i]);
      piece += i + 1 < scene_.placements.size() ? kNext : std::string_view("\n");
      if (piece.size() >= kPieceBytes) {
        sink(std::string_view(piece));
        piece.clear();
      }
    }
    piece += " ";
    piece.append(doc_, open_end_, std::string::npos);
    piece += "\n";
    sink(std::string_view(piece));
  }

 private:
  void appendLine(std::string& out, const Placement& p) const {
    out += kAtOpen;
    appendDecimal(out, p.at[0]);
    out += kComma;
    appendDecimal(out, p.at[1]);
    out += kComma;
    appendDecimal(out, p.at[2]);
    out += kBlock;
    out += quoted_.at(p.block);
    out += kRot;
    appendDecimal(out, p.rot);
    out += kClose;
  }

  const Scene& scene_;
  const std::string doc_;
  size_t open_end_ = 0;
  std::map<std::string, std::string> quoted_;  // block name -> its JSON string
};

}  // namespace

std::string sceneToJson(const Scene& scene) {
  const SceneJsonWriter writer(scene);
  // One pass to size the string, one to fill it: a large scene's text is never held twice.
  size_t bytes = 0;
  writer.write([&bytes](std::string_view piece) { bytes += piece.size(); });
  std::string out;
  out.reserve(bytes);
  writer.write([&out](std::string_view piece) { out += piece; });
  return out;
}

Status saveSceneFile(const std::string& path, const Scene& scene) {
  const SceneJsonWriter writer(scene);
  return writeFileAtomicStreamed(path, [&writer](const FileSink& sink) { writer.write(sink); });
}

}  // namespace rdm
