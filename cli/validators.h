#pragma once
// Option checks with messages a user can act on ("--steps: expected a whole number from 1 to
// 10000000, got '0'"). The ranges are the ones the scenario and map readers use (core::Range), so
// a flag accepts exactly what a file accepts.
#include <CLI/CLI.hpp>

#include <algorithm>

#include <string>
#include <vector>

#include "core/format.h"
#include "core/range.h"
#include "core/suggest.h"

namespace fleetmap::cli {

// A number in `range`; the text stays as typed (CLI11 then converts it).
inline CLI::Validator in_range(const core::Range& range) {
  return CLI::Validator(
      [range](std::string& text) -> std::string {
        if (core::parse_in_range(text, range)) return {};
        return "expected " + core::expected_text(range) + ", got '" + text + "'";
      },
      "NUMBER");
}

// One of `names` (a family's members, a fixed set of words); a mistyped one gets the nearest name.
inline CLI::Validator one_of(std::vector<std::string> names) {
  return CLI::Validator(
      [names](std::string& text) -> std::string {
        if (std::find(names.begin(), names.end(), text) != names.end()) return {};
        return "unknown value '" + text + "'" + core::did_you_mean(text, names) + " (valid: " + core::join(names) + ")";
      },
      "NAME");
}

// --max-cells of every command that reads maps.
inline constexpr core::Range kMaxCellsRange{1, 1e12, true};

// A seed: a whole number from 0 to 2^64 - 1.
inline CLI::Validator seed_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (core::parse_seed(text)) return {};
        return std::string("expected ") + core::kSeedExpected + ", got '" + text + "'";
      },
      "SEED");
}

}  // namespace fleetmap::cli
