#include "viz/render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>
#include "core/error.h"

namespace fleetmap::viz {

namespace {

const cv::Vec3b kUnknown(205, 205, 205), kFree(255, 255, 255), kOccupied(0, 0, 0);

cv::Scalar bgr(const Color& c) { return {double(c.b), double(c.g), double(c.r)}; }

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.5;

// Pixel position of a world point in an image drawn at `scale` pixels per cell.
cv::Point2d to_pixel(const core::GridGeometry& geometry, double scale, const Eigen::Vector2d& p) {
  const Eigen::Vector2d g = geometry.world_to_grid(p);
  return {g.x() * scale, (geometry.height() - g.y()) * scale};
}

cv::Point rounded(const cv::Point2d& p) { return {int(std::lround(p.x)), int(std::lround(p.y))}; }

void draw_dashed(cv::Mat& img, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, int thickness,
                 double& phase) {
  const double dash = 8.0 * thickness / 2.0 + 4.0, len = cv::norm(b - a);
  if (len <= 0.0) return;
  const cv::Point2d dir = (b - a) / len;
  double s = 0.0;
  while (s < len) {
    const double period_pos = std::fmod(phase + s, 2.0 * dash);
    const double step = std::min(len - s, (period_pos < dash ? dash : 2.0 * dash) - period_pos);
    if (period_pos < dash) cv::line(img, rounded(a + dir * s), rounded(a + dir * (s + step)), colour, thickness, cv::LINE_AA);
    s += step;
  }
  phase += len;
}

double nice_length(double target) {
  const double p = std::pow(10.0, std::floor(std::log10(target)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * p <= target) return m * p;
  }
  return p;
}

std::string format_metres(double m) {
  return m >= 1.0 ? fmt::format("{:g} m", m) : fmt::format("{:g} cm", m * 100.0);
}

struct LegendEntry {
  enum Kind { Swatch, Line, Dashed, Disc, Dot } kind;
  cv::Scalar colour;
  std::string label;
};

}  // namespace

Color palette_color(int k) {
  static const Color kColors[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                  {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                  {188, 189, 34}, {23, 190, 207}};
  return kColors[static_cast<unsigned>(k) % 10];
}

cv::Mat colorize(const mapping::OccupancyGrid& grid) {
  cv::Mat img(grid.height(), grid.width(), CV_8UC3);
  for (int row = 0; row < grid.height(); ++row) {
    auto* p = img.ptr<cv::Vec3b>(row);
    const int y = grid.height() - 1 - row;
    const int base = y * grid.width();
    for (int x = 0; x < grid.width(); ++x) {
      switch (grid.state_at(base + x)) {
        case mapping::CellState::Unknown: p[x] = kUnknown; break;
        case mapping::CellState::Free: p[x] = kFree; break;
        case mapping::CellState::Occupied: p[x] = kOccupied; break;
      }
    }
  }
  return img;
}

cv::Mat decorate(const cv::Mat& base, const core::GridGeometry& geometry, const Overlays& overlays,
                 const RenderOptions& options) {
  if (base.empty() || base.type() != CV_8UC3 || base.cols != geometry.width() || base.rows != geometry.height()) {
    throw Error("decorate: base image must be BGR with one pixel per grid cell");
  }
  const int longest = std::max(base.cols, base.rows);
  double scale = 1.0;
  if (longest < options.target_size_px) scale = std::min(16, (options.target_size_px + longest - 1) / longest);
  if (longest > options.max_size_px) scale = double(options.max_size_px) / longest;

  // Cells are blended at one pixel per cell, before scaling, so they stay crisp.
  cv::Mat map = base.clone();
  std::vector<LegendEntry> legend = {{LegendEntry::Swatch, cv::Scalar(205, 205, 205), "unknown"},
                                     {LegendEntry::Swatch, cv::Scalar(255, 255, 255), "free"},
                                     {LegendEntry::Swatch, cv::Scalar(0, 0, 0), "occupied"}};
  for (const auto& layer : overlays.cells) {
    const cv::Vec3d c(layer.color.b, layer.color.g, layer.color.r);
    for (const auto& cell : layer.cells) {
      if (!geometry.contains(cell)) continue;
      auto& px = map.at<cv::Vec3b>(geometry.height() - 1 - cell.y, cell.x);
      for (int k = 0; k < 3; ++k) px[k] = cv::saturate_cast<uchar>((1.0 - layer.opacity) * px[k] + layer.opacity * c[k]);
    }
    if (!layer.label.empty()) legend.push_back({LegendEntry::Swatch, bgr(layer.color), layer.label});
  }
  cv::Mat img;
  if (scale >= 1.0) cv::resize(map, img, {}, scale, scale, cv::INTER_NEAREST);
  else cv::resize(map, img, {}, scale, scale, cv::INTER_AREA);

  for (const auto& path : overlays.paths) {
    const int t = std::max(1, path.thickness_px * (scale >= 1.0 ? 1 : 1));
    double phase = 0.0;
    for (std::size_t i = 1; i < path.points.size(); ++i) {
      const auto a = to_pixel(geometry, scale, path.points[i - 1]), b = to_pixel(geometry, scale, path.points[i]);
      if (path.dashed) draw_dashed(img, a, b, bgr(path.color), t, phase);
      else cv::line(img, rounded(a), rounded(b), bgr(path.color), t, cv::LINE_AA);
    }
    if (!path.label.empty()) legend.push_back({path.dashed ? LegendEntry::Dashed : LegendEntry::Line, bgr(path.color), path.label});
  }
  for (const auto& layer : overlays.points) {
    for (const auto& p : layer.points) {
      cv::circle(img, rounded(to_pixel(geometry, scale, p)), layer.radius_px, bgr(layer.color), cv::FILLED, cv::LINE_AA);
    }
    if (!layer.label.empty()) legend.push_back({LegendEntry::Dot, bgr(layer.color), layer.label});
  }
  for (const auto& pose : overlays.poses) {
    const auto c = to_pixel(geometry, scale, pose.pose.position());
    const int r = std::max(4, int(std::lround(pose.radius_m / geometry.resolution() * scale)));
    cv::circle(img, rounded(c), r, bgr(pose.color), cv::FILLED, cv::LINE_AA);
    cv::circle(img, rounded(c), r, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    const cv::Point2d tip = c + cv::Point2d(std::cos(pose.pose.theta), -std::sin(pose.pose.theta)) * (r * 1.8);
    cv::line(img, rounded(c), rounded(tip), cv::Scalar(0, 0, 0), 2, cv::LINE_AA);
    if (!pose.label.empty()) legend.push_back({LegendEntry::Disc, bgr(pose.color), pose.label});
  }

  const bool has_panel = options.legend || !options.title.empty();
  // The scale bar goes in the legend panel, or on the map when there is no panel.
  const double px_per_m = scale / geometry.resolution();
  const double bar_m = nice_length(std::min(0.25 * img.cols, 180.0) / px_per_m);
  const int bar_px = int(std::lround(bar_m * px_per_m));
  const std::string bar_text = format_metres(bar_m);
  const auto draw_scale_bar = [&](cv::Mat& target, cv::Point o) {
    cv::rectangle(target, cv::Point(o.x, o.y - 6), cv::Point(o.x + bar_px, o.y), cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(target, bar_text, cv::Point(o.x, o.y - 10), kFont, kFontScale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  };
  if (!has_panel) {
    if (options.scale_bar) {
      const cv::Size ts = cv::getTextSize(bar_text, kFont, kFontScale, 1, nullptr);
      const cv::Point o(10, img.rows - 10);
      cv::rectangle(img, cv::Point(o.x - 5, o.y - ts.height - 18), cv::Point(o.x + std::max(bar_px, ts.width) + 5, o.y + 5),
                    cv::Scalar(255, 255, 255), cv::FILLED);
      draw_scale_bar(img, o);
    }
    return img;
  }

  constexpr int kRow = 22, kPad = 10, kSwatch = 14;
  int panel_w = std::max(160, bar_px + 2 * kPad);
  if (!options.title.empty()) panel_w = std::max(panel_w, cv::getTextSize(options.title, kFont, 0.6, 1, nullptr).width + 2 * kPad);
  for (const auto& e : legend) panel_w = std::max(panel_w, cv::getTextSize(e.label, kFont, kFontScale, 1, nullptr).width + 3 * kPad + kSwatch + 10);
  const int title_h = options.title.empty() ? 0 : 30;
  const int rows = options.legend ? int(legend.size()) : 0;
  const int scale_h = options.scale_bar ? 40 : 0;
  const int panel_h = title_h + rows * kRow + scale_h + 2 * kPad;
  cv::Mat out(std::max(img.rows, panel_h), img.cols + panel_w, CV_8UC3, cv::Scalar(255, 255, 255));
  img.copyTo(out(cv::Rect(0, 0, img.cols, img.rows)));
  cv::line(out, cv::Point(img.cols, 0), cv::Point(img.cols, out.rows - 1), cv::Scalar(160, 160, 160), 1);
  int y = kPad;
  const int x0 = img.cols + kPad;
  if (!options.title.empty()) {
    cv::putText(out, options.title, cv::Point(x0, y + 16), kFont, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    y += title_h;
  }
  if (options.legend) {
    for (const auto& e : legend) {
      const cv::Point c(x0 + kSwatch / 2, y + kRow / 2);
      switch (e.kind) {
        case LegendEntry::Swatch:
          cv::rectangle(out, cv::Rect(x0, y + 4, kSwatch, kSwatch), e.colour, cv::FILLED);
          cv::rectangle(out, cv::Rect(x0, y + 4, kSwatch, kSwatch), cv::Scalar(90, 90, 90), 1);
          break;
        case LegendEntry::Line: cv::line(out, c - cv::Point(8, 0), c + cv::Point(8, 0), e.colour, 3, cv::LINE_AA); break;
        case LegendEntry::Dashed: {
          double phase = 0.0;
          draw_dashed(out, c - cv::Point(8, 0), c + cv::Point(8, 0), e.colour, 2, phase);
          break;
        }
        case LegendEntry::Disc:
          cv::circle(out, c, 6, e.colour, cv::FILLED, cv::LINE_AA);
          cv::circle(out, c, 6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
          break;
        case LegendEntry::Dot: cv::circle(out, c, 4, e.colour, cv::FILLED, cv::LINE_AA); break;
      }
      cv::putText(out, e.label, cv::Point(x0 + kSwatch + kPad, y + 16), kFont, kFontScale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      y += kRow;
    }
  }
  if (options.scale_bar) draw_scale_bar(out, cv::Point(x0, y + scale_h - 6));
  return out;
}

}  // namespace fleetmap::viz
