#include "core/suggest.h"

#include <algorithm>
#include <cctype>

namespace fleetmap::core {

namespace {

char lower(char c) { return char(std::tolower(static_cast<unsigned char>(c))); }

bool starts_with_ignoring_case(std::string_view text, std::string_view prefix) {
  if (prefix.size() > text.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (lower(text[i]) != lower(prefix[i])) return false;
  }
  return true;
}

}  // namespace

int edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  // Three rows of the table: i - 2, i - 1 and i.
  std::vector<int> two(m + 1), one(m + 1), row(m + 1);
  for (std::size_t j = 0; j <= m; ++j) one[j] = int(j);
  for (std::size_t i = 1; i <= n; ++i) {
    row[0] = int(i);
    for (std::size_t j = 1; j <= m; ++j) {
      const int cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      row[j] = std::min({one[j] + 1, row[j - 1] + 1, one[j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1])) {
        row[j] = std::min(row[j], two[j - 2] + 1);
      }
    }
    std::swap(two, one);
    std::swap(one, row);
  }
  return one[m];
}

std::optional<std::string> closest_name(std::string_view word, const std::vector<std::string>& names) {
  if (word.empty() || names.empty()) return std::nullopt;
  if (std::find(names.begin(), names.end(), word) != names.end()) return std::nullopt;
  std::optional<std::string> best;
  int best_distance = 0;
  for (const auto& name : names) {
    const int d = edit_distance(word, name);
    const int allowed = int(std::max(word.size(), name.size())) / 3;
    // A prefix either way counts as close, but below any real edit match of the same length.
    const bool prefix = word.size() >= 2 && (starts_with_ignoring_case(name, word) || starts_with_ignoring_case(word, name));
    if (d > allowed && !prefix) continue;
    if (!best || d < best_distance) best = name, best_distance = d;
  }
  return best;
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& names) {
  const auto name = closest_name(word, names);
  return name ? " (did you mean '" + *name + "'?)" : std::string();
}

}  // namespace fleetmap::core
