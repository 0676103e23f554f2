#pragma once
// Option checks with messages a user can act on ("--steps: expected a number > 0, got '0'"), in
// place of CLI11's built-in ones that print the whole range of a double.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <string>

namespace fleetmap::cli {

namespace detail {
inline bool parse_finite(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(value);
}
}  // namespace detail

// A finite number greater than zero.
inline CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0.0;
        if (detail::parse_finite(text, v) && v > 0.0) return {};
        return "expected a number > 0, got '" + text + "'";
      },
      "POSITIVE");
}

// A finite number greater than or equal to zero.
inline CLI::Validator non_negative() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0.0;
        if (detail::parse_finite(text, v) && v >= 0.0) return {};
        return "expected a number >= 0, got '" + text + "'";
      },
      "NONNEGATIVE");
}

// A whole number of decimal digits (seeds: no sign, no exponent, fits 64 bits).
inline CLI::Validator whole_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool digits = !text.empty() && text.size() <= 19 && text.find_first_not_of("0123456789") == std::string::npos;
        if (digits) return {};
        return "expected a whole number >= 0, got '" + text + "'";
      },
      "UINT");
}

}  // namespace fleetmap::cli
