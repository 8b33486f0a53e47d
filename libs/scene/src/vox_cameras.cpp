#include "vox_cameras.h"

#include <cmath>
#include <map>
#include <sstream>

namespace rdm::vox {

glm::dvec3 WorldToScene::operator()(const glm::dvec3& w) const {
  return glm::dvec3(w.x - lo[0], w.z - lo[2], hi[1] + 1.0 - w.y) / 16.0;
}

namespace {

constexpr double kFovDeg = 50.0;

struct View {
  const char* name;
  glm::dvec3 from;  // towards the camera from the box's centre, scene axes (+Z: MV front)
};

// Left and right as seen from the front; the top view leans 3 degrees towards the front so
// that it is not parallel to Y (cameraUsable).
const View kViews[] = {
    {"default", {0.45, 0.75, 1.4}}, {"front", {0.0, 0.0, 1.0}}, {"back", {0.0, 0.0, -1.0}},
    {"left", {-1.0, 0.0, 0.0}},     {"right", {1.0, 0.0, 0.0}}, {"top", {0.0, 1.0, 0.0524}},
    {"iso", {1.0, 1.0, 1.0}},
};

// Looks at the centre of the box lo..hi from `from`, far enough that the box's bounding sphere
// fits the vertical field of view (the horizontal one is wider at every usual aspect).
Camera frameBox(const glm::dvec3& lo, const glm::dvec3& hi, const View& view) {
  const glm::dvec3 centre = (lo + hi) * 0.5;
  const double radius = std::max(0.5 * glm::length(hi - lo), 0.25);
  const double distance = 1.1 * radius / std::sin(glm::radians(kFovDeg) * 0.5);
  return {centre + glm::normalize(view.from) * distance, centre, kFovDeg, view.name};
}

// Three numbers of an attribute ("1 2 3"); false when fewer parse or one is not finite.
bool numbers(const Dict& d, const char* key, int count, double* out) {
  auto it = d.find(key);
  if (it == d.end()) return false;
  std::istringstream in(it->second);
  for (int i = 0; i < count; ++i) {
    if (!(in >> out[i]) || !std::isfinite(out[i])) return false;
  }
  return true;
}

// An rCAM as a scene camera, or why not. Assumed convention (no sample file saves a camera):
// _angle is pitch, yaw, roll in degrees; at 0 0 0 the camera is _radius voxels from _focus on
// the -Y side; pitch raises it, yaw turns it about +Z; roll is dropped.
Expected<Camera> convertCamera(int id, const Dict& d, const WorldToScene& to_scene) {
  const std::string mode = d.count("_mode") ? d.at("_mode") : "pers";
  if (mode != "pers" && mode != "free")
    return Status::error("projection '" + mode + "' (only perspective cameras)");
  double focus[3], angle[3], radius = 0, fov = 45;
  if (!numbers(d, "_focus", 3, focus) || !numbers(d, "_angle", 3, angle) ||
      !numbers(d, "_radius", 1, &radius))
    return Status::error("_focus, _angle or _radius missing or malformed");
  if (d.count("_fov") && !numbers(d, "_fov", 1, &fov)) return Status::error("_fov malformed");
  if (focus[0] == 0 && focus[1] == 0 && focus[2] == 0 && angle[0] == 0 && angle[1] == 0 &&
      angle[2] == 0 && radius <= 1)
    return Status::error("left at MagicaVoxel's defaults (never set)");
  if (!(radius > 0 && radius < 1e6) || !(fov >= 1 && fov <= 170))
    return Status::error("_radius or _fov out of range");
  const double pitch = glm::radians(angle[0]), yaw = glm::radians(angle[1]);
  const glm::dvec3 f(focus[0], focus[1], focus[2]);
  const glm::dvec3 out(std::sin(yaw) * std::cos(pitch), -std::cos(yaw) * std::cos(pitch),
                       std::sin(pitch));
  Camera c{to_scene(f + radius * out), to_scene(f), fov, "file_" + std::to_string(id)};
  if (!cameraUsable(c)) return Status::error("looks straight up or down");
  return c;
}

}  // namespace

std::vector<Camera> voxCameras(glm::dvec3 lo, glm::dvec3 hi, const std::array<int, 3>& size,
                               const VoxFile& f, const WorldToScene& to_scene,
                               std::vector<std::string>& mapped,
                               std::vector<std::string>& dropped) {
  if (lo.x > hi.x) lo = glm::dvec3(0.0), hi = glm::dvec3(size[0], size[1], size[2]);
  std::vector<Camera> cameras;
  for (const View& view : kViews) cameras.push_back(frameBox(lo, hi, view));
  mapped.push_back(
      "0 'default' (three-quarter view from MagicaVoxel's front, its -Y side, from above and "
      "the right), then 'front', 'back', 'left', 'right', 'top', 'iso', each framing the model");
  std::map<std::string, std::vector<int>> refused;
  for (const auto& [id, attributes] : f.cameras) {
    auto c = convertCamera(id, attributes, to_scene);
    if (c) {
      cameras.push_back(*c);
      mapped.push_back("'" + c->name + "' from rCAM " + std::to_string(id) +
                       " (orientation convention assumed: pitch, yaw; roll dropped)");
    } else {
      refused[c.error()].push_back(id);
    }
  }
  for (const auto& [why, ids] : refused) {
    std::string line =
        ids.size() == 1 ? "camera rCAM " : std::to_string(ids.size()) + " cameras (rCAM ";
    for (size_t i = 0; i < ids.size(); ++i) line += (i ? ", " : "") + std::to_string(ids[i]);
    dropped.push_back(line + (ids.size() == 1 ? "" : ")") + " not imported: " + why);
  }
  return cameras;
}

}  // namespace rdm::vox
