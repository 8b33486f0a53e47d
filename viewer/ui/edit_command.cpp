#include "edit_command.h"

#include <sstream>
#include <vector>

namespace rdm::viewer {
namespace {

bool parseTriple(const std::string& text, int lo, int hi, glm::ivec3& out) {
  std::stringstream in(text);
  std::string part;
  std::vector<int> v;
  while (std::getline(in, part, ',')) {
    size_t used = 0;
    try {
      v.push_back(std::stoi(part, &used));
    } catch (const std::exception&) {
      return false;
    }
    if (used != part.size() || v.back() < lo || v.back() > hi) return false;
  }
  if (v.size() != 3) return false;
  out = {v[0], v[1], v[2]};
  return true;
}

bool parseIntIn(const std::string& text, int lo, int hi, int& out) {
  size_t used = 0;
  try {
    out = std::stoi(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == text.size() && out >= lo && out <= hi;
}

Status bad(const std::string& text, const std::string& why) {
  return Status::invalid("--edit", "--edit '" + text + "': " + why);
}

std::string slotText(const glm::ivec3& s) {
  return "(" + std::to_string(s.x) + ", " + std::to_string(s.y) + ", " + std::to_string(s.z) + ")";
}

}  // namespace

Expected<EditCommand> parseEditCommand(const std::string& text) {
  std::stringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  EditCommand e;
  if (words.size() < 2)
    return bad(text,
               "expected 'remove I,J,K', 'add I,J,K BLOCK [ROT]' or "
               "'paint I,J,K X,Y,Z PALETTE'");
  if (!parseTriple(words[1], 0, 4095, e.slot)) return bad(text, "slot must be I,J,K");
  if (words[0] == "remove" && words.size() == 2) {
    e.kind = EditCommand::Kind::kRemove;
  } else if (words[0] == "add" && (words.size() == 3 || words.size() == 4)) {
    e.kind = EditCommand::Kind::kAdd;
    e.block = words[2];
    if (words.size() == 4 && !parseIntIn(words[3], 0, 23, e.rot))
      return bad(text, "ROT must be 0..23");
  } else if (words[0] == "paint" && words.size() == 4) {
    e.kind = EditCommand::Kind::kPaint;
    if (!parseTriple(words[2], 0, 15, e.voxel)) return bad(text, "voxel must be X,Y,Z in 0..15");
    if (!parseIntIn(words[3], 0, 255, e.palette)) return bad(text, "PALETTE must be 0..255");
  } else {
    return bad(text, "unknown edit or wrong number of words");
  }
  return e;
}

Status applyEditCommand(const EditCommand& e, SceneEditor& editor) {
  switch (e.kind) {
    case EditCommand::Kind::kRemove:
      if (!editor.removeBlock(e.slot))
        return bad("remove", "slot " + slotText(e.slot) + " is empty");
      return {};
    case EditCommand::Kind::kAdd:
      if (!editor.addBlock(e.slot, e.block, e.rot))
        return bad("add", "slot " + slotText(e.slot) + " is occupied or outside the grid, or the " +
                              "scene has no block '" + e.block + "'");
      return {};
    case EditCommand::Kind::kPaint:
      if (e.palette > int(editor.scene().palette.size()))
        return bad("paint",
                   "the palette has " + std::to_string(editor.scene().palette.size()) + " entries");
      if (!editor.setVoxel(e.slot * 16 + e.voxel, uint8_t(e.palette)))
        return bad("paint", "slot " + slotText(e.slot) + " holds no block");
      return {};
  }
  return {};
}

}  // namespace rdm::viewer
