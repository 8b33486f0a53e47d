// Scene JSON read in one pass (docs/api.md, "Flags and limits"): `placements`, the only
// part of a scene that grows with the grid, goes into a compact list (20 bytes a placement
// instead of about 450 in nlohmann's DOM); the rest becomes a DOM under the same budget.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <unordered_map>
#include <vector>

#include "rdm/base/json_parse.h"

namespace rdm {

struct CompactPlacement {
  int32_t at[3];
  uint32_t block;  // index into PlacementList::names
  uint8_t rot;
};

struct PlacementList {
  bool present = false;
  std::deque<CompactPlacement> items;  // chunks: no doubling, no copy while it grows
  std::vector<std::string> names;
  // The first malformed element: its index and the loader's message naming the field.
  long long error_index = -1;
  std::string error;
  std::string error_field;  // path of the offending value
};

class SceneSax {
 public:
  using json = nlohmann::json;
  SceneSax(json& root, size_t budget_bytes, PlacementList& out);

  bool null();
  bool boolean(bool v);
  bool number_integer(json::number_integer_t v);
  bool number_unsigned(json::number_unsigned_t v);
  bool number_float(json::number_float_t v, const json::string_t& s);
  bool string(json::string_t& v);
  bool binary(json::binary_t& v);
  bool start_object(std::size_t n);
  bool key(json::string_t& k);
  bool end_object();
  bool start_array(std::size_t n);
  bool end_array();
  bool parse_error(std::size_t position, const std::string& token,
                   const nlohmann::detail::exception& e);
  const Status& error() const { return dom_.error(); }

 private:
  enum class State { kDom, kArray, kElement, kAt, kSkip };
  // A scalar inside the placements; `integer` holds it when it is an integer.
  bool scalar(bool is_integer, long long integer);
  bool open(bool array);
  bool close();
  void elementError(const std::string& what, const std::string& field_suffix);
  void finishElement();
  std::string elementPath() const;

  LimitedDomSax dom_;
  PlacementList& out_;
  std::unordered_map<std::string, uint32_t> ids_;
  std::string top_key_;
  State state_ = State::kDom, after_skip_ = State::kDom;
  int skip_depth_ = 0;
  bool push_after_skip_ = false;
  // The element being read.
  std::string key_;
  CompactPlacement cur_{};
  bool has_at_ = false, has_block_ = false, bad_ = false;
  int at_n_ = 0;
  std::string at_error_;
};

}  // namespace rdm
