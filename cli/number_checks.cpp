#include "number_checks.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <optional>

namespace rdm::cli {
namespace {

// What a value must be: whole or not, within [lo, hi], a power of two when asked.
struct NumberRule {
  bool whole = true;
  double lo = 0.0, hi = double(LLONG_MAX);
  bool power_of_two = false;
  std::string words;  // "must be ...", the message without the value
};

// `text` as a number when all of it is one (a whole one for `whole`), finite.
std::optional<double> parseNumber(const std::string& text, bool whole) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double value =
      whole ? double(std::strtoll(text.c_str(), &end, 10)) : std::strtod(text.c_str(), &end);
  if (errno != 0 || *end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

bool isPowerOfTwo(double v) {
  const long long n = (long long)v;
  return n > 0 && (n & (n - 1)) == 0;
}

std::string checkNumber(const NumberRule& rule, const std::string& input) {
  const std::optional<double> v = parseNumber(input, rule.whole);
  const bool ok = v && *v >= rule.lo && *v <= rule.hi && (!rule.power_of_two || isPowerOfTwo(*v));
  return ok ? std::string() : rule.words + ", got '" + input + "'";
}

CLI::Validator makeCheck(NumberRule rule, const std::string& description) {
  CLI::Validator check([rule](std::string& input) { return checkNumber(rule, input); }, description,
                       "rdm_number");
  return check;
}

std::string zeroWords(const std::string& zero_means) {
  return zero_means.empty() ? "0" : "0 (" + zero_means + ")";
}

// The rule CLI11's PositiveNumber or NonNegativeNumber stands for on `option`; nullopt for
// any other validator.
std::optional<NumberRule> cli11Rule(const CLI::Validator& v, const CLI::Option& option) {
  if (!v.get_name().empty()) return std::nullopt;  // ours, or named by the caller
  const std::string kind = v.get_description();
  if (kind != "POSITIVE" && kind != "NONNEGATIVE") return std::nullopt;
  const std::string type = option.get_type_name();
  const bool whole = type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0;
  const bool positive = kind == "POSITIVE";
  NumberRule rule;
  rule.whole = whole;
  rule.lo = positive && whole ? 1.0 : 0.0;
  rule.hi = whole ? double(LLONG_MAX) : HUGE_VAL;
  rule.words = std::string("must be ") + (positive ? "" : "0 or ") + "a positive " +
               (whole ? "whole number" : "number");
  if (positive && !whole) rule.lo = std::nextafter(0.0, 1.0);
  return rule;
}

}  // namespace

CLI::Validator positiveCount() {
  return makeCheck({true, 1.0, double(LLONG_MAX), false, "must be a positive whole number"},
                   "POSITIVE");
}

CLI::Validator countOrZero(const std::string& zero_means) {
  return makeCheck({true, 0.0, double(LLONG_MAX), false,
                    "must be " + zeroWords(zero_means) + " or a positive whole number"},
                   "NONNEGATIVE");
}

CLI::Validator positiveNumber() {
  return makeCheck({false, std::nextafter(0.0, 1.0), HUGE_VAL, false, "must be a number above 0"},
                   "POSITIVE");
}

CLI::Validator numberOrZero(const std::string& zero_means) {
  return makeCheck(
      {false, 0.0, HUGE_VAL, false, "must be " + zeroWords(zero_means) + " or a positive number"},
      "NONNEGATIVE");
}

CLI::Validator wholeNumberIn(long long lo, long long hi) {
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  return makeCheck(
      {true, double(lo), double(hi), false,
       "must be a whole number from " + std::to_string(lo) + " to " + std::to_string(hi)},
      range);
}

CLI::Validator powerOfTwoIn(long long lo, long long hi) {
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  return makeCheck(
      {true, double(lo), double(hi), true,
       "must be a power of two from " + std::to_string(lo) + " to " + std::to_string(hi)},
      "POWER OF TWO " + range);
}

CLI::Validator anyNumber() {
  return makeCheck({false, -HUGE_VAL, HUGE_VAL, false, "must be a number"}, "NUMBER");
}

void wordNumberChecks(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    for (int i = 0;; ++i) {
      CLI::Validator* v = nullptr;
      try {
        v = option->get_validator(i);
      } catch (const CLI::OptionNotFound&) {
        break;  // past the last validator
      }
      if (auto rule = cli11Rule(*v, *option)) {
        v->operation([rule = *rule](std::string& input) { return checkNumber(rule, input); });
      }
    }
  }
}

}  // namespace rdm::cli
