// number_options — the one rule for numeric command-line options.
//
// CLI11 2.1 converts an unsigned option with strtoull, so "--seed -5" becomes
// 2^64 - 5, a value past 2^64 - 1 saturates silently and "010" is octal; its
// NonNegativeNumber message prints DBL_MAX in full. Every numeric option of
// `autumn` takes one of these validators instead. They check the text before
// CLI11 converts it (decimal digits only, within the range; no option of
// `autumn` takes a negative number) and fail with one line that CLI11 prefixes with the
// option's name, e.g. "--seed: -5 is not a whole number from 0 to
// 18446744073709551615". Tests: tests/cli_test.cpp (Cli.NumericOptions*).
#pragma once
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <charconv>
#include <climits>
#include <cstdint>
#include <string>

namespace autumn::cli {

// A decimal integer in [lo, hi]; no sign ('-' or '+'), no other base.
inline CLI::Validator whole_number(uint64_t lo, uint64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        uint64_t v = 0;
        const char* e = text.data() + text.size();
        const auto [p, ec] = std::from_chars(text.data(), e, v);
        const bool ok = !text.empty() && text[0] != '-' && ec == std::errc() && p == e && v >= lo && v <= hi;
        return ok ? "" : text + " is not a whole number from " + std::to_string(lo) + " to " + std::to_string(hi);
      },
      "[" + std::to_string(lo) + " - " + std::to_string(hi) + "]");
}

// Seeds: any 64-bit unsigned value.
inline CLI::Validator seed_number() { return whole_number(0, UINT64_MAX); }
// Counts held in an int (steps, depths): lo up to INT_MAX.
inline CLI::Validator int_count(uint64_t lo = 0) { return whole_number(lo, INT_MAX); }
// Counts held in a uint64_t (rollouts, nodes): lo up to 2^64 - 1.
inline CLI::Validator big_count(uint64_t lo = 0) { return whole_number(lo, UINT64_MAX); }
// --threads (0: all cores); more than 1,024 is a typo, not a machine.
inline CLI::Validator thread_count() { return whole_number(0, 1024); }

// A decimal number (seconds) of at least `lo`; `name` (NONNEGATIVE, POSITIVE) in --help.
inline CLI::Validator number_at_least(double lo, const std::string& name) {
  return CLI::Validator(
      [lo](std::string& text) -> std::string {
        double v = 0;
        const char* e = text.data() + text.size();
        const auto [p, ec] = std::from_chars(text.data(), e, v);
        if (!text.empty() && ec == std::errc() && p == e && v >= lo && v <= 1e300) return "";
        return text + " is not a number of at least " + fmt::format("{}", lo);
      },
      name);
}

}  // namespace autumn::cli
