#include "merging/evaluation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/angle.h"
#include "core/error.h"

namespace fleetmap::merging {

namespace {

std::vector<cv::Point2f> window(const core::Transform2& to_source, int width, int height) {
  std::vector<cv::Point2f> poly;
  for (const auto& c : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(width - 0.5, -0.5),
                        Eigen::Vector2d(width - 0.5, height - 0.5), Eigen::Vector2d(-0.5, height - 0.5)}) {
    const Eigen::Vector2d p = to_source.apply(c);
    poly.emplace_back(float(p.x()), float(p.y()));
  }
  return poly;
}

std::vector<cv::Point2f> intersect(const std::vector<cv::Point2f>& p, const std::vector<cv::Point2f>& q) {
  std::vector<cv::Point2f> out;
  if (p.empty() || q.empty()) return out;
  cv::intersectConvexConvex(p, q, out, true);
  return out;
}

double area(const std::vector<cv::Point2f>& p) { return p.size() < 3 ? 0.0 : cv::contourArea(p); }

}  // namespace

TransformError transform_error(const core::Transform2& estimate, const core::Transform2& truth,
                               const Eigen::Vector2d& reference) {
  return {std::abs(core::rad2deg(core::normalize_angle(estimate.rotation() - truth.rotation()))),
          (estimate.apply(reference) - truth.apply(reference)).norm()};
}

double mean_displacement(const Eigen::Matrix<double, 2, 3>& estimate, const core::Transform2& truth,
                         const mapping::OccupancyGrid& b) {
  // The difference of two affine maps is affine: D q = (A - R) q + (s - t).
  Eigen::Matrix<double, 2, 3> d = estimate;
  d.leftCols<2>() -= truth.rotation_matrix();
  d.col(2) -= truth.translation();
  double sum = 0.0;
  std::int64_t n = 0;
  for (int y = 0; y < b.height(); ++y) {
    const int row = y * b.width();
    const Eigen::Vector2d start = d.col(1) * double(y) + d.col(2);
    for (int x = 0; x < b.width(); ++x) {
      if (b.state_at(row + x) == mapping::CellState::Unknown) continue;
      sum += (start + d.col(0) * double(x)).norm();
      ++n;
    }
  }
  return n > 0 ? sum / double(n) : 0.0;
}

double mean_displacement(const core::Transform2& estimate, const core::Transform2& truth,
                         const mapping::OccupancyGrid& b) {
  Eigen::Matrix<double, 2, 3> m;
  m << estimate.rotation_matrix(), estimate.translation();
  return mean_displacement(m, truth, b);
}

mapping::OccupancyGrid resample_grid(const mapping::OccupancyGrid& grid, const core::Transform2& frame_to_grid,
                                     int width, int height) {
  mapping::OccupancyGrid out(core::GridGeometry(grid.resolution(), width, height), grid.options());
  const Eigen::Matrix2d r = frame_to_grid.rotation_matrix();
  const Eigen::Vector2d t = frame_to_grid.translation();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector2d p = r * Eigen::Vector2d(x, y) + t;
      const core::Cell c{int(std::lround(p.x())), int(std::lround(p.y()))};
      if (grid.contains(c)) out.set_log_odds({x, y}, grid.log_odds(c));
    }
  }
  return out;
}

mapping::OccupancyGrid crop_grid(const mapping::OccupancyGrid& grid, int x0, int y0, int width, int height,
                                 const core::Pose2& origin) {
  // resample_grid without the turn: a copy of the rows (a resampled cell costs a rounding call).
  mapping::OccupancyGrid out(core::GridGeometry(grid.resolution(), width, height, origin), grid.options());
  const std::vector<float>& from = grid.log_odds_data();
  const int xs = std::max(0, -x0), xe = std::min(width, grid.width() - x0);
  for (int y = std::max(0, -y0); y < std::min(height, grid.height() - y0); ++y) {
    const float* row = from.data() + std::size_t(y + y0) * std::size_t(grid.width());
    for (int x = xs; x < xe; ++x) {
      const float l = row[x + x0];
      if (l != 0.0f) out.set_log_odds({x, y}, l);
    }
  }
  return out;
}

namespace {

struct Windows {
  core::Transform2 a_to_source, b_to_source;
  double overlap = 0.0;
  Eigen::Vector2d overlap_centre_b;
};

// Where the two crops lie on a source of the given size (see CropPairOptions).
Windows choose_windows(int source_width, int source_height, const CropPairOptions& options, core::Random& random) {
  const int w = options.width, h = options.height;
  if (w <= 0 || h <= 0 || w > source_width || h > source_height) {
    throw Error("crop pair: crops of " + std::to_string(w) + "x" + std::to_string(h) + " do not fit a " +
                std::to_string(source_width) + "x" + std::to_string(source_height) + " map");
  }
  const auto src = window(core::Transform2::identity(), source_width, source_height);
  const double crop_area = double(w) * h;
  for (int attempt = 0; attempt < options.max_tries; ++attempt) {
    Windows out;
    out.a_to_source =
        core::Transform2(random.uniform_int(0, source_width - w), random.uniform_int(0, source_height - h), 0.0);
    const double phi = core::deg2rad(random.uniform(-options.max_rotation_deg, options.max_rotation_deg));
    const double dir = random.uniform(-std::numbers::pi, std::numbers::pi);
    const Eigen::Vector2d u(std::cos(dir), std::sin(dir));
    const Eigen::Vector2d centre((w - 1) / 2.0, (h - 1) / 2.0);
    const Eigen::Vector2d centre_a = out.a_to_source.apply(centre);
    const auto poly_a = intersect(window(out.a_to_source, w, h), src);
    // b's frame: turned by phi about its centre, which lies `dist` from a's centre along u.
    const auto b_frame = [&](double dist) {
      const core::Transform2 rot(0.0, 0.0, phi);
      return core::Transform2(centre_a + dist * u - rot.apply(centre), phi);
    };
    const auto overlap_at = [&](double dist) {
      const auto poly_b = intersect(window(b_frame(dist), w, h), src);
      const double common = area(intersect(poly_a, poly_b));
      return common / std::max(1.0, std::min(area(poly_a), area(poly_b)));
    };
    double lo = 0.0, hi = 2.0 * std::hypot(w, h);
    if (options.overlap > 0.0) {
      if (overlap_at(lo) < options.overlap) continue;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (overlap_at(mid) >= options.overlap ? lo : hi) = mid;
      }
    } else {
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (overlap_at(mid) > 0.0 ? lo : hi) = mid;
      }
      lo = hi + options.gap;
    }
    out.b_to_source = b_frame(lo);
    const auto poly_b = intersect(window(out.b_to_source, w, h), src);
    if (area(poly_a) < options.min_inside * crop_area || area(poly_b) < options.min_inside * crop_area) continue;
    out.overlap = overlap_at(lo);
    if (options.overlap > 0.0 && std::abs(out.overlap - options.overlap) > 0.01) continue;
    if (options.overlap <= 0.0 && out.overlap > 0.0) continue;
    const auto common = intersect(poly_a, poly_b);
    out.overlap_centre_b = centre;
    if (common.size() >= 3) {
      const cv::Moments m = cv::moments(common);
      if (m.m00 > 0.0) out.overlap_centre_b = out.b_to_source.inverse().apply(Eigen::Vector2d(m.m10 / m.m00, m.m01 / m.m00));
    }
    return out;
  }
  throw Error("crop pair: no crops of " + std::to_string(w) + "x" + std::to_string(h) + " with overlap " +
              std::to_string(options.overlap) + " fit the map after " + std::to_string(options.max_tries) + " tries");
}

// As choose_windows, with the overlap measured on the source's known cells (OverlapMeasure::Known).
Windows choose_known_windows(const mapping::OccupancyGrid& source, const CropPairOptions& options,
                             core::Random& random) {
  const int w = options.width, h = options.height;
  if (w <= 0 || h <= 0 || options.overlap <= 0.0) {
    throw Error("crop pair: overlap of known cells needs crops of positive size and an overlap above 0");
  }
  // The known cells, thinned to about 100,000 on a regular lattice (each stands for stride^2 cells).
  const std::int64_t known = source.known_count();
  const int stride = std::max(1, int(std::sqrt(double(known) / 1e5)));
  std::vector<Eigen::Vector2d> pts;
  for (int y = 0; y < source.height(); y += stride) {
    for (int x = 0; x < source.width(); x += stride) {
      if (source.state_at(y * source.width() + x) != mapping::CellState::Unknown) pts.emplace_back(x, y);
    }
  }
  const double min_count = options.min_known * double(w) * h / (double(stride) * stride);
  const auto inside = [w, h](const Eigen::Vector2d& q) {
    return q.x() >= -0.5 && q.y() >= -0.5 && q.x() < w - 0.5 && q.y() < h - 0.5;
  };
  std::vector<char> in_a(pts.size());
  for (int attempt = 0; attempt < options.max_tries; ++attempt) {
    Windows out;
    out.a_to_source = core::Transform2(random.uniform_int(-w / 2, std::max(-w / 2, source.width() - w / 2)),
                                       random.uniform_int(-h / 2, std::max(-h / 2, source.height() - h / 2)), 0.0);
    const Eigen::Vector2d to_a = -out.a_to_source.translation();  // a is not turned
    double count_a = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i) count_a += in_a[i] = inside(pts[i] + to_a);
    if (count_a < std::max(1.0, min_count)) continue;
    const double phi = core::deg2rad(random.uniform(-options.max_rotation_deg, options.max_rotation_deg));
    const double dir = random.uniform(-std::numbers::pi, std::numbers::pi);
    const Eigen::Vector2d u(std::cos(dir), std::sin(dir));
    const Eigen::Vector2d centre((w - 1) / 2.0, (h - 1) / 2.0);
    const Eigen::Vector2d centre_a = out.a_to_source.apply(centre);
    const auto b_frame = [&](double dist) {
      const core::Transform2 rot(0.0, 0.0, phi);
      return core::Transform2(centre_a + dist * u - rot.apply(centre), phi);
    };
    struct Shares {
      double overlap = 0.0, count_b = 0.0;
      Eigen::Vector2d centre_b = Eigen::Vector2d::Zero();
    };
    const auto shares_at = [&](double dist) {
      const core::Transform2 to_b = b_frame(dist).inverse();
      const Eigen::Matrix2d r = to_b.rotation_matrix();
      const Eigen::Vector2d t = to_b.translation();
      Shares s;
      double common = 0.0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const Eigen::Vector2d q = r * pts[i] + t;
        if (!inside(q)) continue;
        s.count_b += 1.0;
        if (in_a[i]) common += 1.0, s.centre_b += q;
      }
      s.overlap = s.count_b > 0.0 ? common / std::min(count_a, s.count_b) : 0.0;
      s.centre_b = common > 0.0 ? Eigen::Vector2d(s.centre_b / common) : centre;
      return s;
    };
    // The shared part shrinks, not always monotonically, as b moves away: bisect for a crossing.
    double lo = 0.0, hi = 2.0 * std::hypot(w, h);
    if (shares_at(lo).overlap < options.overlap) continue;
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo + hi);
      (shares_at(mid).overlap >= options.overlap ? lo : hi) = mid;
    }
    const Shares s = shares_at(lo);
    if (s.count_b < std::max(1.0, min_count) || std::abs(s.overlap - options.overlap) > 0.02) continue;
    out.b_to_source = b_frame(lo);
    out.overlap = s.overlap;
    out.overlap_centre_b = s.centre_b;
    return out;
  }
  throw Error("crop pair: no crops of " + std::to_string(w) + "x" + std::to_string(h) + " with " +
              std::to_string(options.overlap) + " of their known cells in common and " +
              std::to_string(options.min_known) + " of their area known fit the map after " +
              std::to_string(options.max_tries) + " tries");
}

CropPair pair_from(const Windows& win) {
  CropPair pair;
  pair.a_to_source = win.a_to_source;
  pair.b_to_source = win.b_to_source;
  pair.b_to_a = win.a_to_source.inverse() * win.b_to_source;
  pair.overlap = win.overlap;
  pair.overlap_centre_b = win.overlap_centre_b;
  return pair;
}

// Cell states while drawing a view.
constexpr std::uint8_t kUnknown = 0, kFree = 1, kOccupied = 2;

cv::Point fixed_point(const Eigen::Vector2d& p) {
  constexpr double kScale = 16.0;  // 4 bits of sub-cell precision for OpenCV's drawing
  return {int(std::lround(p.x() * kScale)), int(std::lround(p.y() * kScale))};
}

}  // namespace

CropPair make_crop_pair(const mapping::OccupancyGrid& source, const CropPairOptions& options, core::Random& random) {
  const Windows win = options.measure == OverlapMeasure::Known
                          ? choose_known_windows(source, options, random)
                          : choose_windows(source.width(), source.height(), options, random);
  CropPair pair = pair_from(win);
  pair.a = resample_grid(source, pair.a_to_source, options.width, options.height);
  pair.b = resample_grid(source, pair.b_to_source, options.width, options.height);
  return pair;
}

CropPair make_world_pair(const SyntheticWorld& world, const CropPairOptions& options, core::Random& random) {
  const Windows win = choose_windows(world.width(), world.height(), options, random);
  CropPair pair = pair_from(win);
  pair.a = world.view(pair.a_to_source, options.width, options.height, random);
  pair.b = world.view(pair.b_to_source, options.width, options.height, random);
  return pair;
}

SyntheticWorld::SyntheticWorld(const SyntheticWorldOptions& options, core::Random& random) : options_(options) {
  if (options.width < 2 * options.min_room || options.height < 2 * options.min_room || options.min_room < 8 ||
      options.max_room < 2 * options.min_room) {
    throw Error("SyntheticWorld: need width, height >= 2 min_room, min_room >= 8 and max_room >= 2 min_room");
  }
  const double w = options.width - 1, h = options.height - 1;
  const auto seg = [&](Eigen::Vector2d a, Eigen::Vector2d b) { walls_.push_back({a, b}); };
  seg({1, 1}, {w - 1, 1});
  seg({w - 1, 1}, {w - 1, h - 1});
  seg({w - 1, h - 1}, {1, h - 1});
  seg({1, h - 1}, {1, 1});
  // A wall from a to b with one or two doors.
  const auto wall_with_doors = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
    const double len = (b - a).norm();
    const Eigen::Vector2d u = (b - a) / len;
    std::vector<double> cuts = {0.0};
    const int doors = len > 4 * options.door_width && random.bernoulli(0.4) ? 2 : 1;
    std::vector<double> at;
    for (int i = 0; i < doors; ++i) at.push_back(random.uniform(options.door_width, len - 2 * options.door_width));
    std::sort(at.begin(), at.end());
    double from = 0.0;
    for (double d : at) {
      if (d > from + 2) seg(a + from * u, a + d * u);
      from = std::max(from, d + options.door_width);
    }
    if (len > from + 2) seg(a + from * u, b);
  };
  struct Box { double x0, y0, x1, y1; };
  std::vector<Box> stack = {{1, 1, w - 1, h - 1}}, rooms;
  while (!stack.empty()) {
    const Box b = stack.back();
    stack.pop_back();
    const double bw = b.x1 - b.x0, bh = b.y1 - b.y0;
    const double longest = std::max(bw, bh);
    if (longest <= options.max_room || (longest < 2.5 * options.min_room && random.bernoulli(0.5))) {
      rooms.push_back(b);
      continue;
    }
    if (bw >= bh) {
      const double x = random.uniform(b.x0 + options.min_room, b.x1 - options.min_room);
      wall_with_doors({x, b.y0}, {x, b.y1});
      stack.push_back({b.x0, b.y0, x, b.y1});
      stack.push_back({x, b.y0, b.x1, b.y1});
    } else {
      const double y = random.uniform(b.y0 + options.min_room, b.y1 - options.min_room);
      wall_with_doors({b.x0, y}, {b.x1, y});
      stack.push_back({b.x0, b.y0, b.x1, y});
      stack.push_back({b.x0, y, b.x1, b.y1});
    }
  }
  for (const auto& r : rooms) {
    const double rw = r.x1 - r.x0, rh = r.y1 - r.y0;
    // A slanted wall cutting off a corner of some rooms.
    if (random.bernoulli(0.15)) {
      const double cx = random.bernoulli(0.5) ? r.x0 : r.x1, cy = random.bernoulli(0.5) ? r.y0 : r.y1;
      const double dx = random.uniform(0.3, 0.6) * rw * (cx == r.x0 ? 1 : -1);
      const double dy = random.uniform(0.3, 0.6) * rh * (cy == r.y0 ? 1 : -1);
      seg({cx + dx, cy}, {cx, cy + dy});
    }
    // Furniture: turned boxes and round pillars, kept inside the room.
    const int n = int(random.uniform(0.0, 2.0 * options.furniture_per_room) + 0.5);
    for (int i = 0; i < n; ++i) {
      const double margin = 6.0;
      if (rw < 4 * margin || rh < 4 * margin) break;
      const Eigen::Vector2d c(random.uniform(r.x0 + 2 * margin, r.x1 - 2 * margin),
                              random.uniform(r.y0 + 2 * margin, r.y1 - 2 * margin));
      const double room = std::min(rw, rh);
      std::vector<Eigen::Vector2d> poly;
      if (random.bernoulli(0.6)) {
        const double a = random.uniform(0.0, std::numbers::pi);
        const double hx = random.uniform(3.0, std::max(4.0, room / 6)), hy = random.uniform(2.0, std::max(3.0, room / 8));
        const core::Transform2 t(c, a);
        for (const auto& q : {Eigen::Vector2d(-hx, -hy), Eigen::Vector2d(hx, -hy), Eigen::Vector2d(hx, hy), Eigen::Vector2d(-hx, hy)}) {
          poly.push_back(t.apply(q));
        }
      } else {
        const double rad = random.uniform(3.0, 9.0);
        for (int k = 0; k < 16; ++k) {
          const double a = 2.0 * std::numbers::pi * k / 16;
          poly.push_back(c + rad * Eigen::Vector2d(std::cos(a), std::sin(a)));
        }
      }
      outlines_.push_back(std::move(poly));
    }
  }
}

mapping::OccupancyGrid SyntheticWorld::view(const core::Transform2& frame_to_world, int width, int height,
                                            core::Random& random) const {
  const core::Transform2 to_frame = frame_to_world.inverse();
  cv::Mat img(height, width, CV_8U, cv::Scalar(kUnknown));
  const cv::Rect frame(-20, -20, width + 40, height + 40);
  const auto visible = [&](const std::vector<cv::Point>& pts) {
    cv::Rect box = cv::boundingRect(pts);
    box = cv::Rect(box.x >> 4, box.y >> 4, (box.width >> 4) + 2, (box.height >> 4) + 2);
    return (box & frame).area() > 0;
  };
  const auto to_points = [&](const std::vector<Eigen::Vector2d>& poly) {
    std::vector<cv::Point> pts;
    for (const auto& p : poly) pts.push_back(fixed_point(to_frame.apply(p)));
    return pts;
  };
  const double wx = options_.width - 1, wy = options_.height - 1;
  const std::vector<Eigen::Vector2d> bounds = {{0, 0}, {wx, 0}, {wx, wy}, {0, wy}};
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{to_points(bounds)}, cv::Scalar(kFree), cv::LINE_8, 4);
  const int t = std::max(1, options_.wall_thickness);
  for (const auto& poly : outlines_) {
    const auto pts = to_points(poly);
    if (!visible(pts)) continue;
    cv::fillPoly(img, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(kUnknown), cv::LINE_8, 4);
    cv::polylines(img, std::vector<std::vector<cv::Point>>{pts}, true, cv::Scalar(kOccupied), t, cv::LINE_8, 4);
  }
  for (const auto& line : walls_) {
    const auto pts = to_points(line);
    if (!visible(pts)) continue;
    cv::polylines(img, std::vector<std::vector<cv::Point>>{pts}, false, cv::Scalar(kOccupied), t, cv::LINE_8, 4);
  }
  mapping::OccupancyGrid grid(core::GridGeometry(0.05, width, height));
  const bool noisy = options_.speckle_rate > 0.0 || options_.wall_gap_rate > 0.0;
  for (int y = 0; y < height; ++y) {
    const auto* row = img.ptr<std::uint8_t>(y);
    for (int x = 0; x < width; ++x) {
      std::uint8_t v = row[x];
      if (noisy) {
        if (v == kFree && options_.speckle_rate > 0.0 && random.bernoulli(options_.speckle_rate)) v = kOccupied;
        else if (v == kOccupied && options_.wall_gap_rate > 0.0 && random.bernoulli(options_.wall_gap_rate)) v = kUnknown;
      }
      if (v == kFree) grid.set_state({x, y}, mapping::CellState::Free);
      else if (v == kOccupied) grid.set_state({x, y}, mapping::CellState::Occupied);
    }
  }
  return grid;
}

}  // namespace fleetmap::merging
