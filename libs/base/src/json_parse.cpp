#include "rdm/base/json_parse.h"

namespace rdm {
namespace {

using nlohmann::json;

// Heap bytes of the DOM, as upper bounds (nlohmann 3.11, libstdc++, glibc malloc, 64-bit):
// an array element is 16 bytes, 48 while its vector grows (old and doubled buffers); an object
// member is a map node of 96; a string past the 15 bytes of the small-string buffer costs its
// characters plus 48; a container's own header 40 (array) or 80 (object).
constexpr size_t kElement = 48, kMember = 96, kStringHeader = 48, kObject = 80, kArray = 40;

}  // namespace

std::string overflowMessage(const std::string& field, const std::string& token) {
  // The token is quoted only when it is a short number, so no other input bytes are echoed.
  const bool plain = !token.empty() && token.size() <= 32 &&
                     token.find_first_not_of("0123456789+-.eE") == std::string::npos;
  const std::string what = plain ? "number " + token + " out of range" : "number out of range";
  return field.empty() ? what : "field '" + field + "': " + what;
}

namespace {

size_t stringCost(size_t n) {
  return n > 15 ? kStringHeader + n : 0;
}

}  // namespace

LimitedDomSax::LimitedDomSax(json& root, size_t budget_bytes, int max_depth)
    : dom_(root, false), budget_(budget_bytes), max_depth_(max_depth) {}

bool LimitedDomSax::null() {
  return value(0) && dom_.null();
}
bool LimitedDomSax::boolean(bool v) {
  return value(0) && dom_.boolean(v);
}
bool LimitedDomSax::number_integer(json::number_integer_t v) {
  return value(0) && dom_.number_integer(v);
}
bool LimitedDomSax::number_unsigned(json::number_unsigned_t v) {
  return value(0) && dom_.number_unsigned(v);
}
bool LimitedDomSax::number_float(json::number_float_t v, const json::string_t& s) {
  return value(0) && dom_.number_float(v, s);
}
bool LimitedDomSax::string(json::string_t& v) {
  return value(stringCost(v.size())) && dom_.string(v);
}
bool LimitedDomSax::binary(json::binary_t& v) {
  return value(v.size() + kStringHeader) && dom_.binary(v);
}
bool LimitedDomSax::start_object(std::size_t n) {
  return open(false, kObject) && dom_.start_object(n);
}
bool LimitedDomSax::key(json::string_t& k) {
  if (!charge(kMember + stringCost(k.size()))) return false;
  frames_.back().key = k;
  return dom_.key(k);
}
bool LimitedDomSax::end_object() {
  frames_.pop_back();
  return dom_.end_object();
}
bool LimitedDomSax::start_array(std::size_t n) {
  return open(true, kArray) && dom_.start_array(n);
}
bool LimitedDomSax::end_array() {
  frames_.pop_back();
  return dom_.end_array();
}

bool LimitedDomSax::parse_error(std::size_t position, const std::string& token,
                                const nlohmann::detail::exception& e) {
  if (!error_.ok()) return false;
  // 406: number overflow. The token is being read, so the path is the next value's.
  if (e.id == 406) {
    value(0);
    const std::string p = path();
    return fail(Status::invalid(p, overflowMessage(p, token)));
  }
  const size_t offset = position > 0 ? position - 1 : 0;
  return fail(
      Status::error(StatusCode::kMalformed, "invalid JSON at byte " + std::to_string(offset)));
}

bool LimitedDomSax::charge(size_t bytes) {
  used_ += bytes;
  if (used_ <= budget_) return true;
  return fail(Status::error(StatusCode::kTooLarge,
                            "JSON document too complex: its parsed form exceeds " +
                                std::to_string(budget_) + " bytes (2.5x the body + 8 MiB)"));
}

bool LimitedDomSax::fail(Status e) {
  RDM_CHECK(!e.ok());
  if (error_.ok()) error_ = std::move(e);
  return false;
}

bool LimitedDomSax::value(size_t cost) {
  if (!frames_.empty() && frames_.back().array) {
    ++frames_.back().index;
    cost += kElement;
  }
  return charge(cost);
}

bool LimitedDomSax::open(bool array, size_t cost) {
  if (!value(cost)) return false;
  if (int(frames_.size()) >= max_depth_) {
    return fail(Status::error(
        StatusCode::kMalformed,
        "invalid JSON: nested deeper than " + std::to_string(max_depth_) + " levels", path()));
  }
  frames_.push_back({array, -1, {}});
  return true;
}

std::string LimitedDomSax::path() const {
  std::string p;
  for (const Frame& f : frames_) {
    if (f.array) {
      p += '[';
      p += std::to_string(f.index < 0 ? 0 : f.index);
      p += ']';
    } else if (!f.key.empty()) {
      if (!p.empty()) p += '.';
      p += f.key;
    }
  }
  return p;
}

Status parseJsonLimited(const std::string& text, json& out, int max_depth) {
  out = json();
  LimitedDomSax sax(out, jsonBudget(text.size()), max_depth);
  const bool ok = json::sax_parse(text, &sax);
  if (ok) return {};
  out = json();  // frees a partial document now
  if (!sax.error().ok()) return sax.error();
  return Status::error(StatusCode::kMalformed, "invalid JSON");
}

}  // namespace rdm
