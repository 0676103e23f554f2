#pragma once
// Numbers and points in messages and tables, formatted one way everywhere (with fmt).
#include <Eigen/Core>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/grid_geometry.h"

namespace fleetmap::core {

// "(1.25, 3.00)": a point in metres, to the centimetre.
inline std::string format_point(const Eigen::Vector2d& p) { return fmt::format("({:.2f}, {:.2f})", p.x(), p.y()); }

// "x from 0.00 to 20.00 m, y from 0.00 to 20.00 m": the box around a grid's corners in metres.
inline std::string format_extent(const GridGeometry& g) {
  double lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
  for (const auto& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(g.width(), 0), Eigen::Vector2d(0, g.height()),
                             Eigen::Vector2d(g.width(), g.height())}) {
    const Eigen::Vector2d w = g.grid_to_world(corner);
    lo_x = std::min(lo_x, w.x()), hi_x = std::max(hi_x, w.x());
    lo_y = std::min(lo_y, w.y()), hi_y = std::max(hi_y, w.y());
  }
  return fmt::format("x from {:.2f} to {:.2f} m, y from {:.2f} to {:.2f} m", lo_x, hi_x, lo_y, hi_y);
}

// `v` with a fixed number of decimals; "inf" / "-inf" for infinities.
inline std::string fixed(double v, int decimals) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:.{}f}", v, decimals);
}

// The shortest text that reads back as exactly `v` ("0.1", "1e-07", "inf").
inline std::string exact(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{}", v);
}

// "a, b, c": the items with `separator` between them.
inline std::string join(const std::vector<std::string>& items, std::string_view separator = ", ") {
  return fmt::format("{}", fmt::join(items, separator));
}

// `s` without leading and trailing spaces and tabs.
inline std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// The items of a comma-separated list, trimmed; an empty item is an InputError naming `what`.
inline std::vector<std::string> split_list(const std::string& text, const std::string& what) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    const std::string item = trim(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (item.empty()) throw InputError(what + ": empty item in the list '" + text + "'");
    out.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace fleetmap::core
