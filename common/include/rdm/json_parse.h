// Linear-time JSON parsing with a nesting limit, for untrusted documents (docs/api.md,
// "Flags and limits"). Builds the DOM through nlohmann's SAX interface, so time and memory
// are linear in the input; error messages never quote the input.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace rdm {

constexpr int kMaxJsonDepth = 64;

struct JsonParseError {
  bool syntax = true;  // malformed or too deep (400); false: a value out of range (422)
  std::string message;
  std::string field;  // path of the offending value, e.g. `palette[2].color[0]`; may be empty
};

// Parses `text` into `out`. Refuses nesting deeper than `max_depth` and numbers that do not
// fit a double (e.g. 1e999), naming the field path.
std::optional<JsonParseError> parseJsonLimited(const std::string& text, nlohmann::json& out,
                                               int max_depth = kMaxJsonDepth);

}  // namespace rdm
