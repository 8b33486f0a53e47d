// Checks for numeric options that say in words what a value must be: CLI11 prefixes the
// option, so a failure reads "--threads: must be 0 (all cores) or a positive whole number, got
// '-1'" (a usage error, exit code 2). Each shows its rule in --help after the type
// ("INT:POSITIVE", "INT:0..65536").
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace rdm::cli {

CLI::Validator positiveCount();                              // 1, 2, ...
CLI::Validator countOrZero(const std::string& zero_means);   // 0 (zero_means), 1, 2, ...
CLI::Validator positiveNumber();                             // any finite number above 0
CLI::Validator numberOrZero(const std::string& zero_means);  // 0 (zero_means) or above
CLI::Validator wholeNumberIn(long long lo, long long hi);    // lo..hi, inclusive
CLI::Validator powerOfTwoIn(long long lo, long long hi);     // lo, 2 lo, ... hi
CLI::Validator anyNumber();                                  // any finite number

// CLI11's own CLI::PositiveNumber and CLI::NonNegativeNumber on the options of `app`, whose
// message reads "Value -1 not in range 0.000000 to 1797...", reworded as the checks above.
void wordNumberChecks(CLI::App& app);

}  // namespace rdm::cli
