// Linear-time JSON parsing with a nesting limit and a memory budget, for untrusted documents
// (docs/api.md, "Flags and limits"). Builds the DOM through nlohmann's SAX interface, so time
// is linear in the input and the parsed form stays within jsonBudget(); error messages never
// quote the input.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/base/status.h"

namespace rdm {

constexpr int kMaxJsonDepth = 64;
// A document's parsed form may take 2.5 times its text plus 8 MiB, so with the text itself
// a refused or accepted body peaks below 4 times its size (docs/deploy.md has the figures).
constexpr size_t jsonBudget(size_t text_bytes) {
  return text_bytes * 5 / 2 + (8u << 20);
}

// Parses `text` into `out`. Refuses, with the code in brackets: bad syntax and nesting deeper
// than `max_depth` (kMalformed), numbers that do not fit a double such as 1e999 (kInvalidInput,
// the field path in field()) and documents whose parsed form would exceed the budget
// (kTooLarge).
Status parseJsonLimited(const std::string& text, nlohmann::json& out,
                        int max_depth = kMaxJsonDepth);

// "field 'F': number T out of range"; T only when it is a short plain number token.
std::string overflowMessage(const std::string& field, const std::string& token);

// The SAX handler behind parseJsonLimited, for parsers that divert part of a document into
// their own compact form (the scene loader's placements). charge() adds to the budget.
class LimitedDomSax {
 public:
  using json = nlohmann::json;
  LimitedDomSax(json& root, size_t budget_bytes, int max_depth);

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

  // False (and an error recorded) when the budget is exceeded.
  bool charge(size_t bytes);
  // Records an error found by a diverting parser; parsing should stop.
  bool fail(Status e);
  const Status& error() const { return error_; }  // ok while none was recorded
  // Path of the value being parsed (e.g. `sun.irradiance[0]`).
  std::string path() const;
  int depth() const { return int(frames_.size()); }

 private:
  struct Frame {
    bool array;
    long long index;
    std::string key;
  };
  bool value(size_t cost);
  bool open(bool array, size_t cost);

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  size_t budget_, used_ = 0;
  int max_depth_;
  std::vector<Frame> frames_;
  Status error_;
};

}  // namespace rdm
