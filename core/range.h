#pragma once
// The numbers a setting accepts, and reading them from text the same way everywhere.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

namespace fleetmap::core {

// The numbers a setting accepts. One value serves the YAML readers and the command-line flags, so
// a value is accepted by both or by neither, with the same words in the message.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool whole = false;      // whole numbers only
  bool allow_inf = false;  // "inf" accepted (and means infinity)
};

// "a whole number from 1 to 100000", "a number >= 0.001 and <= 1000000 (or inf)".
std::string expected_text(const Range& range);
// `text` as a number the range accepts ("inf" where allowed), or nothing.
std::optional<double> parse_in_range(const std::string& text, const Range& range);

// A seed: a whole number from 0 to 18446744073709551615 written in decimal digits.
std::optional<std::uint64_t> parse_seed(const std::string& text);
inline constexpr const char* kSeedExpected = "a whole number from 0 to 18446744073709551615";

}  // namespace fleetmap::core
