#include "core/range.h"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>

namespace fleetmap::core {

namespace {

// Numbers in messages: 100000 rather than 1e+05, 0.001 rather than 0.0010000.
std::string number_text(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (v == std::floor(v) && std::abs(v) < 1e15) return fmt::format("{:.0f}", v);
  return fmt::format("{}", v);
}

}  // namespace

std::string expected_text(const Range& r) {
  const bool has_lo = std::isfinite(r.lo), has_hi = std::isfinite(r.hi);
  std::string text;
  if (r.whole && has_lo && has_hi) {
    text = "a whole number from " + number_text(r.lo) + " to " + number_text(r.hi);
  } else {
    text = r.whole ? "a whole number" : "a number";
    if (has_lo) text += (r.lo == 0.0 && !r.whole ? " >= 0" : " >= " + number_text(r.lo));
    if (has_lo && has_hi) text += " and";
    if (has_hi) text += " <= " + number_text(r.hi);
  }
  if (r.allow_inf) text += " (or inf)";
  return text;
}

std::optional<double> parse_in_range(const std::string& raw, const Range& r) {
  std::string t = raw;
  for (char& ch : t) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (r.allow_inf && (t == "inf" || t == ".inf" || t == "+inf" || t == "infinity" || t == "infinite" || t == "unlimited")) {
    return std::numeric_limits<double>::infinity();
  }
  if (t.empty() || std::isspace(static_cast<unsigned char>(t.front())) || std::isspace(static_cast<unsigned char>(t.back()))) {
    return std::nullopt;
  }
  double v = 0.0;
  const auto [end, ec] = std::from_chars(t.data() + (t.front() == '+' ? 1 : 0), t.data() + t.size(), v);
  if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
  if (r.whole && v != std::floor(v)) return std::nullopt;
  if (v < r.lo || v > r.hi) return std::nullopt;
  return v;
}

std::optional<std::uint64_t> parse_seed(const std::string& text) {
  if (text.empty() || text.size() > 20 || text.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return v;
}

}  // namespace fleetmap::core
