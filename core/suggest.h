#pragma once
// "Did you mean" for a mistyped name: the valid name nearest to what was typed, by edit distance.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fleetmap::core {

// Edits (insertions, deletions, substitutions, swaps of neighbours) that turn `a` into `b`,
// ignoring case (Damerau-Levenshtein, optimal string alignment).
int edit_distance(std::string_view a, std::string_view b);

// The name in `names` nearest to `word`: one within a third of the longer word's length in edits
// (at least one edit), or one that starts with `word` or that `word` starts with (a cut or
// lengthened flag; not for a word of one or two letters). nullopt when nothing is that close, or
// when `word` is itself a name.
std::optional<std::string> closest_name(std::string_view word, const std::vector<std::string>& names);

// " (did you mean 'robots'?)" for the closest name, or "" when there is none.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& names);

}  // namespace fleetmap::core
