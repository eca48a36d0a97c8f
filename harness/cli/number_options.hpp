// number_options — the one rule for numeric command-line options.
//
// CLI11 2.1 converts an unsigned option with strtoull, so "--seed -5" becomes
// 2^64 - 5, a value past 2^64 - 1 saturates silently and "010" is octal; its
// NonNegativeNumber message prints DBL_MAX in full. Every numeric option of
// `autumn` takes one of these validators instead. They check the text before
// CLI11 converts it (decimal digits, a '-' only where negatives are allowed,
// within the range) and fail with one line that CLI11 prefixes with the
// option's name, e.g. "--seed: -5 is not a whole number from 0 to
// 18446744073709551615". Tests: tests/cli_test.cpp (Cli.NumericOptions*).
#pragma once
#include <CLI/CLI.hpp>

#include <charconv>
#include <climits>
#include <cstdint>
#include <string>

namespace autumn::cli {

// A decimal integer in [lo, hi].
inline CLI::Validator whole_number(int64_t lo, uint64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const std::string why = text + " is not a whole number from " + std::to_string(lo) + " to " + std::to_string(hi);
        const bool negative = !text.empty() && text[0] == '-';
        const char* b = text.data() + (negative ? 1 : 0);
        const char* e = text.data() + text.size();
        if (b == e || *b == '+') return why;
        uint64_t magnitude = 0;
        const auto [p, ec] = std::from_chars(b, e, magnitude);
        if (ec != std::errc() || p != e) return why;
        if (negative) {
          if (magnitude == 0) return "";
          if (lo >= 0 || magnitude > static_cast<uint64_t>(INT64_MAX) + 1) return why;
          return static_cast<int64_t>(-(magnitude - 1)) - 1 >= lo ? "" : why;
        }
        if (magnitude > hi || (lo > 0 && magnitude < static_cast<uint64_t>(lo))) return why;
        return "";
      },
      "[" + std::to_string(lo) + " - " + std::to_string(hi) + "]");
}

// Seeds: any 64-bit unsigned value.
inline CLI::Validator seed_number() { return whole_number(0, UINT64_MAX); }
// Counts held in an int (steps, depths): lo up to INT_MAX.
inline CLI::Validator int_count(int64_t lo = 0) { return whole_number(lo, INT_MAX); }
// Counts held in a uint64_t (rollouts, nodes): lo up to 2^64 - 1.
inline CLI::Validator big_count(int64_t lo = 0) { return whole_number(lo, UINT64_MAX); }

// A decimal number (seconds) of at least `lo` (`shown` in messages; `name`, e.g.
// NONNEGATIVE, in --help).
inline CLI::Validator number_at_least(double lo, const std::string& shown, const std::string& name) {
  return CLI::Validator(
      [lo, shown](std::string& text) -> std::string {
        const std::string why = text + " is not a number of at least " + shown;
        double v = 0;
        const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (text.empty() || ec != std::errc() || p != text.data() + text.size() || !(v >= lo) || v > 1e300) return why;
        return "";
      },
      name);
}

}  // namespace autumn::cli
