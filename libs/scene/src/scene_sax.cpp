#include "scene_sax.h"

#include <climits>

namespace rdm {
namespace {

constexpr size_t kItemCost = sizeof(CompactPlacement) + 4;  // deque chunks and map
constexpr size_t kNameCost = 128;                           // map node + two strings

}  // namespace

SceneSax::SceneSax(json& root, size_t budget_bytes, PlacementList& out)
    : dom_(root, budget_bytes, kMaxJsonDepth), out_(out) {}

std::string SceneSax::elementPath() const {
  return "placements[" + std::to_string(out_.items.size()) + "]";
}

void SceneSax::elementError(const std::string& what, const std::string& field_suffix) {
  bad_ = true;
  if (out_.error_index >= 0) return;
  out_.error_index = (long long)out_.items.size();
  out_.error_field = elementPath() + field_suffix;
  out_.error = "field '" + out_.error_field + "': " + what;
}

void SceneSax::finishElement() {
  if (!bad_ && !has_at_) elementError("required", ".at");
  if (!bad_ && !has_block_) elementError("expected a block name", ".block");
  out_.items.push_back(bad_ ? CompactPlacement{} : cur_);
}

bool SceneSax::scalar(bool is_integer, long long v) {
  switch (state_) {
    case State::kArray:
      elementError("expected an object", "");
      out_.items.push_back({});
      return dom_.charge(kItemCost);
    case State::kElement:
      if (key_ == "at") {
        elementError("expected an array of 3 integers", ".at");
      } else if (key_ == "block") {
        elementError("expected a block name", ".block");
      } else if (!is_integer) {
        elementError("expected an integer", ".rot");
      } else if (v < 0 || v > 23) {
        elementError("value " + std::to_string(v) + " outside [0, 23]", ".rot");
      } else {
        cur_.rot = uint8_t(v);
      }
      return true;
    case State::kAt: {
      const int a = at_n_++;
      if (a >= 3 || !at_error_.empty()) return true;
      const std::string field = ".at[" + std::to_string(a) + "]";
      if (!is_integer) {
        at_error_ = field +
                    "\x1f"
                    "expected an integer";
      } else if (v < INT32_MIN || v > INT32_MAX) {
        at_error_ = field +
                    "\x1f"
                    "value " +
                    std::to_string(v) + " outside [" + std::to_string(INT32_MIN) + ", " +
                    std::to_string(INT32_MAX) + "]";
      } else {
        cur_.at[a] = int32_t(v);
      }
      return true;
    }
    default:
      return true;  // kSkip
  }
}

bool SceneSax::null() {
  return state_ == State::kDom ? dom_.null() : scalar(false, 0);
}
bool SceneSax::boolean(bool v) {
  return state_ == State::kDom ? dom_.boolean(v) : scalar(false, 0);
}
bool SceneSax::number_integer(json::number_integer_t v) {
  return state_ == State::kDom ? dom_.number_integer(v) : scalar(true, v);
}
bool SceneSax::number_unsigned(json::number_unsigned_t v) {
  if (state_ == State::kDom) return dom_.number_unsigned(v);
  return scalar(true, v > uint64_t(LLONG_MAX) ? LLONG_MAX : (long long)v);
}
bool SceneSax::number_float(json::number_float_t v, const json::string_t& s) {
  return state_ == State::kDom ? dom_.number_float(v, s) : scalar(false, 0);
}
bool SceneSax::binary(json::binary_t& v) {
  return state_ == State::kDom ? dom_.binary(v) : scalar(false, 0);
}

bool SceneSax::string(json::string_t& v) {
  if (state_ == State::kDom) return dom_.string(v);
  if (state_ != State::kElement || key_ != "block") return scalar(false, 0);
  auto [it, fresh] = ids_.try_emplace(v, uint32_t(out_.names.size()));
  if (fresh) {
    out_.names.push_back(v);
    if (!dom_.charge(kNameCost + 2 * v.size())) return false;
  }
  cur_.block = it->second;
  has_block_ = true;
  return true;
}

bool SceneSax::key(json::string_t& k) {
  if (state_ == State::kDom) {
    if (dom_.depth() == 1) top_key_ = k;
    return dom_.key(k);
  }
  if (state_ != State::kElement) return true;  // kSkip
  key_ = k;
  if (k != "at" && k != "block" && k != "rot") {
    elementError("unknown key", "." + k);
    state_ = State::kSkip, skip_depth_ = 1, after_skip_ = State::kArray, push_after_skip_ = true;
  }
  return true;
}

bool SceneSax::open(bool array) {
  switch (state_) {
    case State::kDom:
      if (array && dom_.depth() == 1 && top_key_ == "placements") {
        out_ = PlacementList{};  // a repeated key replaces the earlier list, as in the DOM
        ids_.clear();
        out_.present = true;
        state_ = State::kArray;
      }
      return array ? dom_.start_array(size_t(-1)) : dom_.start_object(size_t(-1));
    case State::kArray:
      if (!dom_.charge(kItemCost)) return false;
      if (array) {
        elementError("expected an object", "");
        out_.items.push_back({});
        state_ = State::kSkip, skip_depth_ = 1, after_skip_ = State::kArray;
        push_after_skip_ = false;
        return true;
      }
      state_ = State::kElement;
      cur_ = {}, has_at_ = has_block_ = bad_ = false, key_.clear();
      return true;
    case State::kElement:
      if (key_ == "at" && array) {
        state_ = State::kAt, at_n_ = 0, at_error_.clear();
        return true;
      }
      scalar(false, 0);
      state_ = State::kSkip, skip_depth_ = 1, after_skip_ = State::kElement;
      push_after_skip_ = false;
      return true;
    case State::kAt:
      scalar(false, 0);
      state_ = State::kSkip, skip_depth_ = 1, after_skip_ = State::kAt, push_after_skip_ = false;
      return true;
    case State::kSkip:
      if (++skip_depth_ + dom_.depth() + 3 > kMaxJsonDepth) {
        return dom_.fail(Status::error(
            StatusCode::kMalformed,
            "invalid JSON: nested deeper than " + std::to_string(kMaxJsonDepth) + " levels"));
      }
      return true;
  }
  return true;
}

bool SceneSax::close() {
  switch (state_) {
    case State::kDom:
      return false;  // not reached: the caller forwards
    case State::kArray:
      state_ = State::kDom;
      return dom_.end_array();
    case State::kElement:
      finishElement();
      state_ = State::kArray;
      return true;
    case State::kAt:
      if (at_n_ != 3) {
        elementError("expected an array of 3 integers", ".at");
      } else if (!at_error_.empty()) {
        const size_t sep = at_error_.find('\x1f');
        elementError(at_error_.substr(sep + 1), at_error_.substr(0, sep));
      }
      has_at_ = true;
      state_ = State::kElement;
      return true;
    case State::kSkip:
      if (--skip_depth_ == 0) {
        state_ = after_skip_;
        if (push_after_skip_) out_.items.push_back({});
      }
      return true;
  }
  return true;
}

bool SceneSax::start_object(std::size_t) {
  return open(false);
}
bool SceneSax::start_array(std::size_t) {
  return open(true);
}
bool SceneSax::end_object() {
  return state_ == State::kDom ? dom_.end_object() : close();
}
bool SceneSax::end_array() {
  return state_ == State::kDom ? dom_.end_array() : close();
}

bool SceneSax::parse_error(std::size_t position, const std::string& token,
                           const nlohmann::detail::exception& e) {
  if (e.id != 406 || state_ == State::kDom || state_ == State::kSkip)
    return dom_.parse_error(position, token, e);
  std::string field = elementPath();
  if (state_ == State::kElement) field += "." + key_;
  if (state_ == State::kAt) field += ".at[" + std::to_string(at_n_) + "]";
  return dom_.fail(Status::invalid(field, overflowMessage(field, token)));
}

}  // namespace rdm
