#pragma once
// Charts for reports: line plots (a mean with a translucent band or error bars per series) and
// grouped bar charts, with axes, "nice" ticks, a light grid, a title and a legend. Each is a
// Drawing: rasterize() gives the PNG's image, to_svg() the same figure as SVG.
#include <opencv2/core/mat.hpp>

#include <optional>
#include <string>
#include <vector>

#include "viz/drawing.h"
#include "viz/render.h"

namespace fleetmap::viz {

struct PlotSeries {
  std::string label;  // empty: not in the legend
  Color color;
  std::vector<double> x, y;             // same length; NaN y values leave a gap
  std::vector<double> y_low, y_high;    // empty, or one value per point: the band or error bar
  bool markers = false;                 // a dot at every point
  bool dashed = false;                  // e.g. a bound rather than a measurement
};

struct PlotAxis {
  std::string label;
  std::optional<double> min, max;  // unset: from the data, widened to whole ticks
  // Tick values to label (e.g. the team sizes); empty: "nice" ticks. With given ticks, an unset
  // min / max leaves half a tick gap beyond the outer ticks.
  std::vector<double> ticks;
};

struct LinePlot {
  std::string title;
  PlotAxis x, y;
  std::vector<PlotSeries> series;
  // y_low/y_high drawn as a translucent band (true) or as error bars at the points (false).
  // Bands blend where they overlap, so no series hides another's; a line that coincides with a
  // later series' line is drawn wider, so both stay visible. A series with a single point is
  // drawn as a short level line across it.
  bool bands = true;
};

struct BarChart {
  std::string title;
  std::string y_label;
  std::vector<std::string> groups;         // categories along x
  std::vector<std::string> series_labels;  // one bar per series in every group (the legend)
  std::vector<Color> colors;               // per series
  // values[s][g]; NaN = no bar. low/high: empty or the same shape, drawn as error bars.
  std::vector<std::vector<double>> values, low, high;
  std::optional<double> y_min, y_max;      // unset: 0 and the data's maximum
};

struct PlotOptions {
  int width_px = 900;
  int height_px = 560;
};

// Tick values at 1, 2 or 5 times a power of ten covering [lo, hi], about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);
// A tick's label with decimals enough to tell ticks `step` apart ("0.5", "10").
std::string tick_text(double v, double step);

Drawing line_plot(const LinePlot& plot, const PlotOptions& options = {});
Drawing bar_chart(const BarChart& chart, const PlotOptions& options = {});
inline cv::Mat draw_line_plot(const LinePlot& plot, const PlotOptions& options = {}) {
  return rasterize(line_plot(plot, options));
}
inline cv::Mat draw_bar_chart(const BarChart& chart, const PlotOptions& options = {}) {
  return rasterize(bar_chart(chart, options));
}

// Drawings side by side, `columns` per row; cells are as large as the largest drawing.
Drawing tile(const std::vector<Drawing>& drawings, int columns);
// Images side by side, `columns` per row, on white; cells are as large as the largest image.
cv::Mat tile_images(const std::vector<cv::Mat>& images, int columns);

}  // namespace fleetmap::viz
