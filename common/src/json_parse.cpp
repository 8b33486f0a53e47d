#include "rdm/json_parse.h"

#include <vector>

namespace rdm {
namespace {

using nlohmann::json;

// Forwards to nlohmann's own DOM builder and keeps the path of the value being parsed.
class LimitedSax {
 public:
  LimitedSax(json& root, int max_depth) : dom_(root, false), max_depth_(max_depth) {}

  bool null() { return value() && dom_.null(); }
  bool boolean(bool v) { return value() && dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return value() && dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value() && dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const json::string_t& s) {
    return value() && dom_.number_float(v, s);
  }
  bool string(json::string_t& v) { return value() && dom_.string(v); }
  bool binary(json::binary_t& v) { return value() && dom_.binary(v); }
  bool start_object(std::size_t n) { return open(false) && dom_.start_object(n); }
  bool key(json::string_t& k) {
    frames_.back().key = k;
    return dom_.key(k);
  }
  bool end_object() {
    frames_.pop_back();
    return dom_.end_object();
  }
  bool start_array(std::size_t n) { return open(true) && dom_.start_array(n); }
  bool end_array() {
    frames_.pop_back();
    return dom_.end_array();
  }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& e) {
    if (error_) return false;
    // 406: number overflow. The token is being read, so the path is the next value's.
    if (e.id == 406) {
      value();
      error_ = JsonParseError{false, "", path()};
      error_->message = error_->field.empty()
                            ? "number out of range"
                            : "field '" + error_->field + "': number out of range";
      return false;
    }
    const size_t offset = position > 0 ? position - 1 : 0;
    error_ = JsonParseError{true, "invalid JSON at byte " + std::to_string(offset), {}};
    return false;
  }
  std::optional<JsonParseError> error() const { return error_; }

 private:
  struct Frame {
    bool array;
    long long index;
    std::string key;
  };
  // Called before each value: advances the index of the enclosing array.
  bool value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return true;
  }
  bool open(bool array) {
    value();
    if (int(frames_.size()) >= max_depth_) {
      const std::string p = path();
      error_ = JsonParseError{
          true, "invalid JSON: nested deeper than " + std::to_string(max_depth_) + " levels", p};
      return false;
    }
    frames_.push_back({array, -1, {}});
    return true;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.array) {
        p += "[" + std::to_string(f.index < 0 ? 0 : f.index) + "]";
      } else if (!f.key.empty()) {
        p += (p.empty() ? "" : ".") + f.key;
      }
    }
    return p;
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  int max_depth_;
  std::vector<Frame> frames_;
  std::optional<JsonParseError> error_;
};

}  // namespace

std::optional<JsonParseError> parseJsonLimited(const std::string& text, json& out, int max_depth) {
  out = json();
  LimitedSax sax(out, max_depth);
  const bool ok = json::sax_parse(text, &sax);
  if (ok) return std::nullopt;
  out = json();  // frees a partial document now
  if (auto e = sax.error()) return e;
  return JsonParseError{true, "invalid JSON", {}};
}

}  // namespace rdm
