#include "viz/render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>
#include "core/error.h"
#include "viz/drawing.h"
#include "viz/plot.h"

namespace fleetmap::viz {

namespace {

const cv::Vec3b kUnknown(205, 205, 205), kFree(255, 255, 255), kOccupied(0, 0, 0);

cv::Scalar bgr(const Color& c) { return {double(c.b), double(c.g), double(c.r)}; }

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.5;

cv::Point rounded(const cv::Point2d& p) { return {int(std::lround(p.x)), int(std::lround(p.y))}; }

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

const cv::Vec3b kOutside(238, 238, 238);

// Cells [x0, x1) x [y0, y1) of the picture; may reach beyond the grid.
struct CellBox {
  int x0, y0, x1, y1;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  void add(double gx, double gy, int margin) {
    x0 = std::min(x0, int(std::floor(gx)) - margin);
    y0 = std::min(y0, int(std::floor(gy)) - margin);
    x1 = std::max(x1, int(std::floor(gx)) + 1 + margin);
    y1 = std::max(y1, int(std::floor(gy)) + 1 + margin);
  }
};

// The cells to draw: the grid (or its known cells plus the margin), grown to hold every overlay.
CellBox picture_cells(const cv::Mat& base, const core::GridGeometry& geometry, const Overlays& overlays,
                      const RenderOptions& options) {
  CellBox box{0, 0, geometry.width(), geometry.height()};
  if (options.crop_margin_m) {
    const int margin = int(std::ceil(*options.crop_margin_m / geometry.resolution()));
    cv::Mat known;
    cv::inRange(base, cv::Scalar(kUnknown[0], kUnknown[1], kUnknown[2]), cv::Scalar(kUnknown[0], kUnknown[1], kUnknown[2]), known);
    cv::bitwise_not(known, known);
    const cv::Rect r = cv::boundingRect(known);
    if (r.area() > 0) {
      // Image rows run down, grid rows up.
      box = {std::max(0, r.x - margin), std::max(0, geometry.height() - (r.y + r.height) - margin),
             std::min(geometry.width(), r.x + r.width + margin), std::min(geometry.height(), geometry.height() - r.y + margin)};
    }
  }
  // Overlays inside the grid widen the box up to the grid's edge; those outside, beyond it.
  CellBox inside = box, beyond = box;
  const auto add = [&](const Eigen::Vector2d& p, int margin) {
    const Eigen::Vector2d g = geometry.world_to_grid(p);
    if (!std::isfinite(g.x()) || !std::isfinite(g.y())) return;
    const bool in_grid = g.x() >= 0 && g.y() >= 0 && g.x() <= geometry.width() && g.y() <= geometry.height();
    (in_grid ? inside : beyond).add(g.x(), g.y(), margin);
  };
  const int pad = std::max(1, int(std::ceil(0.3 / geometry.resolution())));
  for (const auto& path : overlays.paths) {
    for (const auto& p : path.points) add(p, pad);
  }
  for (const auto& layer : overlays.points) {
    for (const auto& p : layer.points) add(p, pad);
  }
  for (const auto& pose : overlays.poses) add(pose.pose.position(), pad + int(std::ceil(pose.radius_m / geometry.resolution())));
  box = {std::min(beyond.x0, std::max(0, inside.x0)), std::min(beyond.y0, std::max(0, inside.y0)),
         std::max(beyond.x1, std::min(geometry.width(), inside.x1)), std::max(beyond.y1, std::min(geometry.height(), inside.y1))};
  // A picture never grows past four times the grid on a side for overlays far away.
  box.x0 = std::max(box.x0, -geometry.width() * 2);
  box.y0 = std::max(box.y0, -geometry.height() * 2);
  box.x1 = std::min(box.x1, geometry.width() * 3);
  box.y1 = std::min(box.y1, geometry.height() * 3);
  return box;
}

void draw_legend_symbol(cv::Mat& out, const LegendItem& e, cv::Point c, int swatch) {
  const cv::Scalar colour = bgr(e.color);
  switch (e.kind) {
    case LegendItem::Swatch:
      cv::rectangle(out, cv::Rect(c.x - swatch / 2, c.y - swatch / 2, swatch, swatch), colour, cv::FILLED);
      cv::rectangle(out, cv::Rect(c.x - swatch / 2, c.y - swatch / 2, swatch, swatch), cv::Scalar(90, 90, 90), 1);
      break;
    case LegendItem::Line: cv::line(out, c - cv::Point(8, 0), c + cv::Point(8, 0), colour, 3, cv::LINE_AA); break;
    case LegendItem::Dashed: {
      double phase = 0.0;
      draw_dashed_line(out, c - cv::Point(9, 0), c + cv::Point(9, 0), colour, 2, phase);
      break;
    }
    case LegendItem::Disc:
      cv::circle(out, c, 6, colour, cv::FILLED, cv::LINE_AA);
      cv::circle(out, c, 6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      break;
    case LegendItem::Ring: cv::circle(out, c, 6, colour, 2, cv::LINE_AA); break;
    case LegendItem::Dot: cv::circle(out, c, 4, colour, cv::FILLED, cv::LINE_AA); break;
  }
}

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

namespace {

// The cells of the box, one pixel each (cells beyond the grid in the "outside" colour), with the
// overlays' cell layers blended in at one pixel per cell, before scaling, so they stay crisp.
cv::Mat box_cells(const cv::Mat& base, const core::GridGeometry& geometry, const CellBox& box, const Overlays& overlays,
                  const RenderOptions& options, std::vector<LegendItem>& legend) {
  cv::Mat map(box.height(), box.width(), CV_8UC3, cv::Scalar(kOutside[0], kOutside[1], kOutside[2]));
  const cv::Rect in_grid = cv::Rect(box.x0, box.y0, box.width(), box.height()) & cv::Rect(0, 0, geometry.width(), geometry.height());
  if (in_grid.area() > 0) {
    // Grid rows y0..y1 are image rows height-y1..height-y0 of the base, box.y1-y1.. of the map.
    const cv::Rect src(in_grid.x, geometry.height() - (in_grid.y + in_grid.height), in_grid.width, in_grid.height);
    const cv::Rect dst(in_grid.x - box.x0, box.y1 - (in_grid.y + in_grid.height), in_grid.width, in_grid.height);
    base(src).copyTo(map(dst));
  }
  const bool outside = box.x0 < 0 || box.y0 < 0 || box.x1 > geometry.width() || box.y1 > geometry.height();
  legend = options.map_legend ? *options.map_legend
                              : std::vector<LegendItem>{{LegendItem::Swatch, {205, 205, 205}, "unknown"},
                                                        {LegendItem::Swatch, {255, 255, 255}, "free"},
                                                        {LegendItem::Swatch, {0, 0, 0}, "occupied"}};
  if (outside) legend.push_back({LegendItem::Swatch, {kOutside[2], kOutside[1], kOutside[0]}, "outside the grid"});
  for (const auto& layer : overlays.cells) {
    const cv::Vec3d c(layer.color.b, layer.color.g, layer.color.r);
    for (const auto& cell : layer.cells) {
      if (!geometry.contains(cell) || cell.x < box.x0 || cell.x >= box.x1 || cell.y < box.y0 || cell.y >= box.y1) continue;
      auto& px = map.at<cv::Vec3b>(box.y1 - 1 - cell.y, cell.x - box.x0);
      for (int k = 0; k < 3; ++k) px[k] = cv::saturate_cast<uchar>((1.0 - layer.opacity) * px[k] + layer.opacity * c[k]);
    }
    if (!layer.label.empty()) legend.push_back({LegendItem::Swatch, layer.color, layer.label});
  }
  return map;
}

// Paths, points and poses on the scaled map `img`; lines and markers grow with the picture, so
// they stay visible on large maps.
void draw_shapes(cv::Mat& img, const core::GridGeometry& geometry, const CellBox& box, double scale,
                 const Overlays& overlays, const RenderOptions& options, std::vector<LegendItem>& legend) {
  // Pixel position of a world point in `img`.
  const auto to_pixel = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d g = geometry.world_to_grid(p);
    return cv::Point2d((g.x() - box.x0) * scale, (box.y1 - g.y()) * scale);
  };
  const int longest_px = std::max(img.cols, img.rows);
  const double grow = std::max(1.0, longest_px / 1600.0);
  const int min_marker = std::max(options.min_marker_px, int(std::lround(longest_px / 160.0)));
  for (const auto& path : overlays.paths) {
    const int t = std::max(1, int(std::lround(path.thickness_px * grow)));
    double phase = 0.0;
    for (std::size_t i = 1; i < path.points.size(); ++i) {
      const auto a = to_pixel(path.points[i - 1]), b = to_pixel(path.points[i]);
      if (path.dashed) draw_dashed_line(img, a, b, bgr(path.color), t, phase);
      else cv::line(img, rounded(a), rounded(b), bgr(path.color), t, cv::LINE_AA);
    }
    if (!path.label.empty()) legend.push_back({path.dashed ? LegendItem::Dashed : LegendItem::Line, path.color, path.label});
  }
  for (const auto& layer : overlays.points) {
    const int r = std::max(1, int(std::lround(layer.radius_px * grow)));
    for (const auto& p : layer.points) cv::circle(img, rounded(to_pixel(p)), r, bgr(layer.color), cv::FILLED, cv::LINE_AA);
    if (!layer.label.empty()) legend.push_back({LegendItem::Dot, layer.color, layer.label});
  }
  for (const auto& pose : overlays.poses) {
    const auto c = to_pixel(pose.pose.position());
    const int r = std::max(min_marker, int(std::lround(pose.radius_m / geometry.resolution() * scale)));
    const int line = std::max(2, int(std::lround(2 * grow)));
    if (pose.start) {
      cv::circle(img, rounded(c), r, cv::Scalar(255, 255, 255), line + 2, cv::LINE_AA);
      cv::circle(img, rounded(c), r, bgr(pose.color), line, cv::LINE_AA);
    } else {
      cv::circle(img, rounded(c), r, bgr(pose.color), cv::FILLED, cv::LINE_AA);
      cv::circle(img, rounded(c), r, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }
    const cv::Point2d tip = c + cv::Point2d(std::cos(pose.pose.theta), -std::sin(pose.pose.theta)) * (r * 1.8);
    cv::line(img, rounded(c), rounded(tip), pose.start ? bgr(pose.color) : cv::Scalar(0, 0, 0), line, cv::LINE_AA);
    if (!pose.label.empty()) legend.push_back({pose.start ? LegendItem::Ring : LegendItem::Disc, pose.color, pose.label});
  }
}

constexpr double kTickFont = 0.45;

// Metre ticks along the grid from its origin (world metres when the map is not turned).
struct Axes {
  std::vector<double> xticks, yticks;
  int left = 0, bottom = 0;  // pixels their labels need
};

Axes axes_for(const cv::Mat& img, const core::GridGeometry& geometry, const CellBox& box) {
  const auto metres_x = [&](double gx) { return geometry.origin().x + gx * geometry.resolution(); };
  const auto metres_y = [&](double gy) { return geometry.origin().y + gy * geometry.resolution(); };
  Axes a;
  a.xticks = nice_ticks(metres_x(box.x0), metres_x(box.x1), std::max(2, img.cols / 110));
  a.yticks = nice_ticks(metres_y(box.y0), metres_y(box.y1), std::max(2, img.rows / 90));
  const double ystep = a.yticks.size() > 1 ? a.yticks[1] - a.yticks[0] : 1.0;
  int label_w = 0;
  for (double t : a.yticks) label_w = std::max(label_w, cv::getTextSize(tick_text(t, ystep), kFont, kTickFont, 1, nullptr).width);
  a.left = label_w + 40;
  a.bottom = 50;
  return a;
}

void draw_axes(cv::Mat& out, const cv::Rect& map_area, const Axes& axes, const core::GridGeometry& geometry,
               const CellBox& box, double scale) {
  cv::rectangle(out, cv::Rect(map_area.x - 1, map_area.y - 1, map_area.width + 2, map_area.height + 2), cv::Scalar(0, 0, 0), 1);
  const auto& xticks = axes.xticks;
  const auto& yticks = axes.yticks;
  const double xstep = xticks.size() > 1 ? xticks[1] - xticks[0] : 1.0, ystep = yticks.size() > 1 ? yticks[1] - yticks[0] : 1.0;
  const int base_y = map_area.y + map_area.height;
  for (double t : xticks) {
    const int x = map_area.x + int(std::lround(((t - geometry.origin().x) / geometry.resolution() - box.x0) * scale));
    if (x < map_area.x - 1 || x > map_area.x + map_area.width) continue;
    cv::line(out, cv::Point(x, base_y), cv::Point(x, base_y + 5), cv::Scalar(0, 0, 0), 1);
    const std::string text = tick_text(t, xstep);
    const int w = cv::getTextSize(text, kFont, kTickFont, 1, nullptr).width;
    cv::putText(out, text, cv::Point(x - w / 2, base_y + 20), kFont, kTickFont, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  for (double t : yticks) {
    const int y = map_area.y + int(std::lround((box.y1 - (t - geometry.origin().y) / geometry.resolution()) * scale));
    if (y < map_area.y - 1 || y > base_y) continue;
    cv::line(out, cv::Point(map_area.x - 6, y), cv::Point(map_area.x - 1, y), cv::Scalar(0, 0, 0), 1);
    const std::string text = tick_text(t, ystep);
    const int w = cv::getTextSize(text, kFont, kTickFont, 1, nullptr).width;
    cv::putText(out, text, cv::Point(map_area.x - 9 - w, y + 5), kFont, kTickFont, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  const std::string x_label = "x (m)";
  const int xw = cv::getTextSize(x_label, kFont, kFontScale, 1, nullptr).width;
  cv::putText(out, x_label, cv::Point(map_area.x + (map_area.width - xw) / 2, base_y + 42), kFont, kFontScale,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(out, "y (m)", cv::Point(4, map_area.y - 10), kFont, kFontScale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

// A scale bar of a round length (the text above the bar).
struct ScaleBar {
  int px = 0;
  std::string text;
  void draw(cv::Mat& target, cv::Point o) const {
    cv::rectangle(target, cv::Point(o.x, o.y - 6), cv::Point(o.x + px, o.y), cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(target, text, cv::Point(o.x, o.y - 10), kFont, kFontScale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
};

}  // namespace

Picture draw_picture(const cv::Mat& base, const core::GridGeometry& geometry, const Overlays& overlays,
                     const RenderOptions& options) {
  if (base.empty() || base.type() != CV_8UC3 || base.cols != geometry.width() || base.rows != geometry.height()) {
    throw Error("decorate: base image must be BGR with one pixel per grid cell");
  }
  const CellBox box = picture_cells(base, geometry, overlays, options);
  const int longest = std::max(box.width(), box.height());
  double scale = 1.0;
  if (longest < options.target_size_px) scale = std::min(16, (options.target_size_px + longest - 1) / longest);
  if (longest > options.max_size_px) scale = double(options.max_size_px) / longest;

  std::vector<LegendItem> legend;
  const cv::Mat map = box_cells(base, geometry, box, overlays, options, legend);
  cv::Mat img;
  if (scale >= 1.0) cv::resize(map, img, {}, scale, scale, cv::INTER_NEAREST);
  else cv::resize(map, img, {}, scale, scale, cv::INTER_AREA);
  draw_shapes(img, geometry, box, scale, overlays, options, legend);
  legend.insert(legend.end(), overlays.legend.begin(), overlays.legend.end());

  const double px_per_m = scale / geometry.resolution();
  const double bar_m = nice_length(std::min(0.25 * img.cols, 180.0) / px_per_m);
  const ScaleBar bar{int(std::lround(bar_m * px_per_m)), format_metres(bar_m)};
  if (!options.legend && options.scale_bar) {
    const cv::Size ts = cv::getTextSize(bar.text, kFont, kFontScale, 1, nullptr);
    const cv::Point o(10, img.rows - 10);
    cv::rectangle(img, cv::Point(o.x - 5, o.y - ts.height - 18), cv::Point(o.x + std::max(bar.px, ts.width) + 5, o.y + 5),
                  cv::Scalar(255, 255, 255), cv::FILLED);
    bar.draw(img, o);
  }
  const Axes axes = options.axes ? axes_for(img, geometry, box) : Axes{};

  // The page: title above, axes' labels left and below, the legend panel (with the scale bar) right.
  constexpr int kRow = 22, kPad = 10, kSwatch = 14;
  int panel_w = 0, panel_h = 0;
  const int scale_h = options.scale_bar ? 40 : 0;
  if (options.legend) {
    panel_w = std::max(160, bar.px + 2 * kPad);
    for (const auto& e : legend) {
      panel_w = std::max(panel_w, cv::getTextSize(e.label, kFont, kFontScale, 1, nullptr).width + 3 * kPad + kSwatch + 10);
    }
    panel_h = int(legend.size()) * kRow + scale_h + 2 * kPad;
  }
  constexpr double kTitleFont = 0.6;
  const cv::Size title_size = cv::getTextSize(options.title, kFont, kTitleFont, 1, nullptr);
  const int title_h = options.title.empty() ? 0 : title_size.height + 24;
  const int top = title_h + (options.axes ? 24 : 0);
  const int right = options.axes ? 12 : 0;
  const int width = std::max(axes.left + img.cols + right + panel_w, options.title.empty() ? 0 : title_size.width + 2 * kPad);
  const int height = std::max(top + img.rows + axes.bottom, title_h + panel_h);
  cv::Mat out(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect map_area(axes.left, top, img.cols, img.rows);
  img.copyTo(out(map_area));
  if (!options.title.empty()) {
    cv::putText(out, options.title, cv::Point((width - title_size.width) / 2, title_size.height + 12), kFont, kTitleFont,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  if (options.axes) draw_axes(out, map_area, axes, geometry, box, scale);
  if (options.legend) {
    const int x0 = axes.left + img.cols + right + kPad;
    cv::line(out, cv::Point(x0 - kPad, title_h), cv::Point(x0 - kPad, out.rows - 1), cv::Scalar(160, 160, 160), 1);
    int y = title_h + kPad;
    for (const auto& e : legend) {
      draw_legend_symbol(out, e, cv::Point(x0 + kSwatch / 2, y + kRow / 2 + 1), kSwatch);
      cv::putText(out, e.label, cv::Point(x0 + kSwatch + kPad, y + 16), kFont, kFontScale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      y += kRow;
    }
    if (options.scale_bar) bar.draw(out, cv::Point(x0, y + scale_h - 6));
  }
  return {out, map_area, scale, Eigen::Vector2d(box.x0, box.y0)};
}

}  // namespace fleetmap::viz
