// Minimal option parsing for the rdm verbs: `--name value` and `--flag`, positionals kept
// in order. Unknown options are usage errors reported by name.
#pragma once

#include <cstdlib>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "commands.h"

namespace rdm::cli {

class ArgParser {
 public:
  ArgParser(std::set<std::string> value_options, std::set<std::string> flag_options)
      : value_options_(std::move(value_options)), flag_options_(std::move(flag_options)) {}

  // Returns an error message, or empty on success.
  std::string parse(const Args& args) {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (a.rfind("--", 0) != 0 && !(a.size() == 2 && a[0] == '-' && a != "-")) {
        positionals_.push_back(a);
      } else if (flag_options_.count(a)) {
        flags_.insert(a);
      } else if (value_options_.count(a)) {
        if (i + 1 >= args.size()) return "option " + a + " needs a value";
        values_[a] = args[++i];
      } else {
        return "unknown option " + a;
      }
    }
    return {};
  }
  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  std::optional<std::string> value(const std::string& name) const {
    auto it = values_.find(name);
    return it == values_.end() ? std::nullopt : std::optional<std::string>(it->second);
  }
  // Parses an integer option; `error` receives a message when it is malformed.
  std::optional<long long> integer(const std::string& name, std::string& error) const {
    auto v = value(name);
    if (!v) return std::nullopt;
    char* end = nullptr;
    long long x = std::strtoll(v->c_str(), &end, 10);
    if (v->empty() || *end) {
      error = "option " + name + " expects an integer, got '" + *v + "'";
      return std::nullopt;
    }
    return x;
  }
  std::optional<double> number(const std::string& name, std::string& error) const {
    auto v = value(name);
    if (!v) return std::nullopt;
    char* end = nullptr;
    double x = std::strtod(v->c_str(), &end);
    if (v->empty() || *end) {
      error = "option " + name + " expects a number, got '" + *v + "'";
      return std::nullopt;
    }
    return x;
  }
  const std::vector<std::string>& positionals() const { return positionals_; }

 private:
  std::set<std::string> value_options_, flag_options_;
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
  std::vector<std::string> positionals_;
};

}  // namespace rdm::cli
