#include "viz/plot.h"
#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

namespace fleetmap::viz {

namespace {

// A value in a tooltip: whole numbers as such, others with three significant digits.
std::string tip_number(double v) {
  return v == std::round(v) && std::abs(v) < 1e9 ? fmt::format("{:.0f}", v) : fmt::format("{:.3g}", v);
}

constexpr double kTickFont = 0.45;
constexpr double kLabelFont = 0.5;
constexpr double kTitleFont = 0.6;
const Color kBlack{0, 0, 0};
const Color kGrid{225, 225, 225};
constexpr double kBandOpacity = 0.2;

bool finite(double v) { return std::isfinite(v); }

int text_width(const std::string& text, double scale) { return text_size(text, scale).width; }

double tick_step(const std::vector<double>& ticks) { return ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0; }

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!finite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

// The axis range: the user's limits where given, else the data's, widened to whole ticks (or to
// half a gap beyond given ticks).
std::pair<double, double> axis_range(Range data, const std::optional<double>& lo, const std::optional<double>& hi,
                                     const std::vector<double>& given_ticks = {}) {
  if (!given_ticks.empty()) {
    const auto [t0, t1] = std::minmax_element(given_ticks.begin(), given_ticks.end());
    double gap = 1.0;
    for (std::size_t i = 1; i < given_ticks.size(); ++i) {
      const double d = std::abs(given_ticks[i] - given_ticks[i - 1]);
      if (d > 0.0 && (i == 1 || d < gap)) gap = d;
    }
    data.add(*t0);
    data.add(*t1);
    double a = lo.value_or(data.lo - 0.5 * gap), b = hi.value_or(data.hi + 0.5 * gap);
    if (!(b > a)) b = a + 1.0;
    return {a, b};
  }
  if (!finite(data.lo)) data = {0.0, 1.0};
  double a = lo.value_or(data.lo), b = hi.value_or(data.hi);
  if (!(b > a)) {
    const double pad = std::max(1.0, std::abs(a) * 0.1);
    if (!lo) a -= pad;
    if (!hi || !(b > a)) b = a + 2.0 * pad;
  }
  const auto ticks = nice_ticks(a, b);
  const double step = tick_step(ticks);
  if (!lo) a = std::floor(a / step + 1e-9) * step;
  if (!hi) b = std::ceil(b / step - 1e-9) * step;
  return {a, b};
}

struct Frame {
  cv::Rect area;  // the plot area in the canvas
  double x0, x1, y0, y1;
  double px(double x) const { return std::clamp((x - x0) / (x1 - x0) * area.width, -1e4, 1e4); }
  double py(double y) const { return std::clamp((1.0 - (y - y0) / (y1 - y0)) * area.height, -1e4, 1e4); }
  // Canvas coordinates of a data point.
  cv::Point2d point(double x, double y) const { return {area.x + px(x), area.y + py(y)}; }
};

struct LegendEntry {
  std::string label;
  Color color;
  bool box = false;  // a filled square (bars) or a line (series)
  double width = 3.0;
  bool dashed = false;
};

int legend_width(const std::vector<LegendEntry>& entries) {
  int w = 0;
  for (const auto& e : entries) w = std::max(w, text_width(e.label, kLabelFont));
  return entries.empty() ? 20 : w + 60;
}

void draw_legend(Drawing& d, const std::vector<LegendEntry>& entries, int x, int y) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int row = y + int(i) * 22;
    const auto& e = entries[i];
    if (e.box) {
      d.rect(cv::Rect2d(x, row - 10, 22, 12), e.color);
    } else {
      d.line(cv::Point2d(x, row - 4), cv::Point2d(x + 24, row - 4), e.color, std::min(e.width, 6.0), e.dashed);
    }
    d.text(cv::Point2d(x + 32, row), e.label, kLabelFont);
  }
}

// Canvas, title, y ticks with grid lines and y label; returns the frame for the data.
Frame draw_frame(Drawing& d, const std::string& title, const std::string& y_label, double y0, double y1, int legend_w,
                 const PlotOptions& options, const std::vector<double>& given_ticks = {}) {
  const auto ticks = given_ticks.empty() ? nice_ticks(y0, y1) : given_ticks;
  int tick_w = 0;
  for (double t : ticks) tick_w = std::max(tick_w, text_width(tick_text(t, tick_step(ticks)), kTickFont));
  const int left = tick_w + 45, top = 45, bottom = 62, right = legend_w + 15;
  // A title wider than the canvas widens it: titles are never cut.
  const int width = std::max(options.width_px, text_width(title, kTitleFont) + 20);
  d = Drawing(width, options.height_px);
  Frame f{cv::Rect(left, top, std::max(50, width - left - right), std::max(50, options.height_px - top - bottom)),
          0.0, 1.0, y0, y1};
  d.text(cv::Point2d(width / 2.0, 28), title, kTitleFont, TextAnchor::Middle);
  for (double t : ticks) {
    if (t < y0 - 1e-9 * (y1 - y0) || t > y1 + 1e-9 * (y1 - y0)) continue;
    const double y = f.point(0.0, t).y;
    d.line({double(f.area.x), y}, {double(f.area.x + f.area.width), y}, kGrid);
    d.line({f.area.x - 5.0, y}, {double(f.area.x), y}, kBlack);
    d.text({f.area.x - 8.0, y + 5}, tick_text(t, tick_step(ticks)), kTickFont, TextAnchor::End);
  }
  d.vertical_text({14.0, f.area.y + f.area.height / 2.0}, y_label, kLabelFont);
  return f;
}

void finish_frame(Drawing& d, const Frame& f, const std::string& x_label) {
  d.end_clip();
  const double l = f.area.x, t = f.area.y, r = f.area.x + f.area.width, b = f.area.y + f.area.height;
  d.polyline({{l, t}, {r, t}, {r, b}, {l, b}, {l, t}}, kBlack);
  d.text({(l + r) / 2.0, b + 50}, x_label, kLabelFont, TextAnchor::Middle);
}

// Index ranges [begin, end) of consecutive points with finite x and y.
std::vector<std::pair<std::size_t, std::size_t>> runs_of_finite(const PlotSeries& s) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  const std::size_t n = std::min(s.x.size(), s.y.size());
  std::size_t i = 0;
  while (i < n) {
    while (i < n && !(finite(s.x[i]) && finite(s.y[i]))) ++i;
    const std::size_t begin = i;
    while (i < n && finite(s.x[i]) && finite(s.y[i])) ++i;
    if (i > begin) out.emplace_back(begin, i);
  }
  return out;
}

bool has_band(const PlotSeries& s) { return s.y_low.size() == s.y.size() && s.y_high.size() == s.y.size(); }

}  // namespace

std::string tick_text(double v, double step) {
  const int decimals = std::clamp(int(-std::floor(std::log10(step) + 1e-9)), 0, 6);
  return fmt::format("{:.{}f}", std::abs(v) < step * 1e-9 ? 0.0 : v, decimals);
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!finite(lo) || !finite(hi)) return {};
  if (hi < lo) std::swap(lo, hi);
  if (hi == lo) return {lo};
  const double raw = (hi - lo) / std::max(1, target);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  // The step of 1, 2, 5 or 10 times the magnitude whose number of gaps is nearest the target.
  double step = magnitude;
  for (double m : {2.0, 5.0, 10.0}) {
    if (std::abs((hi - lo) / (m * magnitude) - target) < std::abs((hi - lo) / step - target)) step = m * magnitude;
  }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + step * 1e-9; t += step) {
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
    if (ticks.size() > 1000) break;
  }
  return ticks;
}

namespace {

// The line width of each series: 2 px, plus 2 px for every later series whose line lies on this
// one (within half a percent of the y range at more than half the shared x values), so lines that
// coincide (e.g. every strategy with a single robot) stay visible as nested stripes.
std::vector<double> line_widths(const std::vector<PlotSeries>& series, double y_range) {
  std::vector<double> widths(series.size(), 2.0);
  const double tol = 0.005 * y_range;
  for (std::size_t j = 1; j < series.size(); ++j) {
    std::map<double, double> later;
    for (std::size_t b = 0; b < std::min(series[j].x.size(), series[j].y.size()); ++b) {
      if (finite(series[j].y[b])) later[series[j].x[b]] = series[j].y[b];
    }
    for (std::size_t i = 0; i < j; ++i) {
      int shared = 0, same = 0;
      for (std::size_t a = 0; a < std::min(series[i].x.size(), series[i].y.size()); ++a) {
        const auto it = later.find(series[i].x[a]);
        if (it == later.end() || !finite(series[i].y[a])) continue;
        ++shared;
        same += std::abs(series[i].y[a] - it->second) <= tol;
      }
      if (shared > 0 && 2 * same > shared) widths[i] = std::min(widths[i] + 2.0, 12.0);
    }
  }
  return widths;
}

}  // namespace

Drawing line_plot(const LinePlot& plot, const PlotOptions& options) {
  Range xr, yr;
  for (const auto& s : plot.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!finite(s.x[i]) || !finite(s.y[i])) continue;
      xr.add(s.x[i]);
      yr.add(s.y[i]);
      if (has_band(s)) yr.add(s.y_low[i]), yr.add(s.y_high[i]);
    }
  }
  const auto [x0, x1] = axis_range(xr, plot.x.min, plot.x.max, plot.x.ticks);
  const auto [y0, y1] = axis_range(yr, plot.y.min, plot.y.max, plot.y.ticks);
  const std::vector<double> widths = line_widths(plot.series, y1 - y0);
  std::vector<LegendEntry> legend;
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const auto& s = plot.series[k];
    if (!s.label.empty()) legend.push_back({s.label, s.color, false, std::max(3.0, widths[k]), s.dashed});
  }
  Drawing d;
  Frame f = draw_frame(d, plot.title, plot.y.label, y0, y1, legend_width(legend), options, plot.y.ticks);
  f.x0 = x0;
  f.x1 = x1;
  const auto xticks = plot.x.ticks.empty() ? nice_ticks(x0, x1, std::max(2, f.area.width / 90)) : plot.x.ticks;
  const double bottom = f.area.y + f.area.height;
  for (double t : xticks) {
    if (t < x0 || t > x1) continue;
    const double x = f.point(t, 0.0).x;
    d.line({x, double(f.area.y)}, {x, bottom}, kGrid);
    d.line({x, bottom}, {x, bottom + 5}, kBlack);
    d.text({x, bottom + 22}, tick_text(t, tick_step(xticks)), kTickFont, TextAnchor::Middle);
  }

  d.begin_clip(f.area);
  // Each band is blended on its own, so where bands overlap both colours show.
  if (plot.bands) {
    for (const auto& s : plot.series) {
      if (!has_band(s)) continue;
      for (const auto& [b, e] : runs_of_finite(s)) {
        std::vector<cv::Point2d> poly;
        for (std::size_t i = b; i < e; ++i) poly.push_back(f.point(s.x[i], s.y_high[i]));
        for (std::size_t i = e; i-- > b;) poly.push_back(f.point(s.x[i], s.y_low[i]));
        if (e - b == 1) {  // one point: the band is a short bar
          const cv::Point2d hi = poly[0], lo = poly[1];
          poly = {hi + cv::Point2d(-6, 0), hi + cv::Point2d(6, 0), lo + cv::Point2d(6, 0), lo + cv::Point2d(-6, 0)};
        }
        d.polygon(poly, s.color, kBandOpacity);
        d.set_role("band");
      }
    }
  }
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const auto& s = plot.series[k];
    for (const auto& [b, e] : runs_of_finite(s)) {
      std::vector<cv::Point2d> line;
      for (std::size_t i = b; i < e; ++i) line.push_back(f.point(s.x[i], s.y[i]));
      // A single point is a short level line, so a one-value series (e.g. a bound at one team size) shows.
      if (line.size() == 1) line = {line[0] + cv::Point2d(-24, 0), line[0] + cv::Point2d(24, 0)};
      d.polyline(line, s.color, widths[k], s.dashed);
      d.set_role("series");
      for (std::size_t i = b; i < e; ++i) {
        if (!plot.bands && has_band(s) && finite(s.y_low[i]) && finite(s.y_high[i])) {
          const cv::Point2d lo = f.point(s.x[i], s.y_low[i]), hi = f.point(s.x[i], s.y_high[i]);
          d.line(lo, hi, s.color);
          d.line(lo - cv::Point2d(4, 0), lo + cv::Point2d(4, 0), s.color);
          d.line(hi - cv::Point2d(4, 0), hi + cv::Point2d(4, 0), s.color);
        }
        if (s.markers) d.circle(f.point(s.x[i], s.y[i]), 2.0 + widths[k], s.color);
      }
      // Tooltips (SVG) at up to 60 points of the run: the series, x, y and the band or bar.
      const std::size_t every = std::max<std::size_t>(1, (e - b + 59) / 60);
      for (std::size_t i = b; i < e; i += every) {
        std::string tip = fmt::format("{}{}{} {}: {} {}", s.label, s.label.empty() ? "" : "\n", plot.x.label.empty() ? "x" : plot.x.label,
                                      tip_number(s.x[i]), plot.y.label.empty() ? "y" : plot.y.label, tip_number(s.y[i]));
        if (has_band(s) && finite(s.y_low[i]) && finite(s.y_high[i]))
          tip += fmt::format(" [{}, {}]", tip_number(s.y_low[i]), tip_number(s.y_high[i]));
        d.hover_spot(f.point(s.x[i], s.y[i]), 2.0 + widths[k] + 3.0, std::move(tip));
      }
    }
  }
  finish_frame(d, f, plot.x.label);
  draw_legend(d, legend, f.area.x + f.area.width + 15, f.area.y + 14);
  return d;
}

Drawing bar_chart(const BarChart& chart, const PlotOptions& options) {
  const std::size_t n_series = chart.values.size(), n_groups = chart.groups.size();
  const auto value = [](const std::vector<std::vector<double>>& v, std::size_t s, std::size_t g) {
    return s < v.size() && g < v[s].size() ? v[s][g] : std::numeric_limits<double>::quiet_NaN();
  };
  Range yr;
  yr.add(0.0);
  for (std::size_t s = 0; s < n_series; ++s) {
    for (std::size_t g = 0; g < n_groups; ++g) {
      yr.add(value(chart.values, s, g));
      yr.add(value(chart.high, s, g));
    }
  }
  const auto [y0, y1] = axis_range(yr, chart.y_min.value_or(0.0), chart.y_max);
  std::vector<LegendEntry> legend;
  for (std::size_t s = 0; s < n_series; ++s) {
    const Color c = s < chart.colors.size() ? chart.colors[s] : palette_color(int(s));
    legend.push_back({s < chart.series_labels.size() ? chart.series_labels[s] : "", c, true});
  }
  Drawing d;
  Frame f = draw_frame(d, chart.title, chart.y_label, y0, y1, legend_width(legend), options);
  f.x0 = 0.0;
  f.x1 = double(std::max<std::size_t>(1, n_groups));
  d.begin_clip(f.area);
  const double slot = 0.8 / double(std::max<std::size_t>(1, n_series));
  for (std::size_t g = 0; g < n_groups; ++g) {
    for (std::size_t s = 0; s < n_series; ++s) {
      const double v = value(chart.values, s, g);
      if (!finite(v)) continue;
      const double left = double(g) + 0.1 + slot * double(s);
      const cv::Point2d a = f.point(left + 0.05 * slot, std::max(y0, 0.0)), b = f.point(left + 0.95 * slot, v);
      d.rect(cv::Rect2d(a, b), legend[s].color);
      d.set_role("bar");
      const double lo = value(chart.low, s, g), hi = value(chart.high, s, g);
      d.set_tooltip(fmt::format("{}{}{}: {}{}", s < chart.series_labels.size() ? chart.series_labels[s] : "",
                                g < chart.groups.size() ? ", " : "", g < chart.groups.size() ? chart.groups[g] : "",
                                tip_number(v), finite(lo) && finite(hi) ? fmt::format(" [{}, {}]", tip_number(lo), tip_number(hi)) : ""));
      if (finite(lo) && finite(hi)) {
        const double mid = left + 0.5 * slot;
        const cv::Point2d p = f.point(mid, lo), q = f.point(mid, hi);
        d.line(p, q, kBlack);
        d.line(p - cv::Point2d(4, 0), p + cv::Point2d(4, 0), kBlack);
        d.line(q - cv::Point2d(4, 0), q + cv::Point2d(4, 0), kBlack);
      }
    }
  }
  d.end_clip();
  for (std::size_t g = 0; g < n_groups; ++g) {
    const double cx = f.point(double(g) + 0.5, 0.0).x;
    const int room = int(f.area.width / double(std::max<std::size_t>(1, n_groups)));
    const double scale = std::min(kLabelFont, kLabelFont * room / double(std::max(1, text_width(chart.groups[g], kLabelFont) + 8)));
    d.text({cx, f.area.y + f.area.height + 22.0}, chart.groups[g], scale, TextAnchor::Middle);
  }
  finish_frame(d, f, "");
  draw_legend(d, legend, f.area.x + f.area.width + 15, f.area.y + 14);
  return d;
}

Drawing tile(const std::vector<Drawing>& drawings, int columns) {
  if (drawings.empty()) return {};
  columns = std::clamp(columns, 1, int(drawings.size()));
  int w = 0, h = 0;
  for (const auto& d : drawings) w = std::max(w, d.width()), h = std::max(h, d.height());
  const int rows = (int(drawings.size()) + columns - 1) / columns;
  Drawing out(columns * w, rows * h);
  for (std::size_t k = 0; k < drawings.size(); ++k) {
    out.place(drawings[k], cv::Point2d(int(k) % columns * w, int(k) / columns * h));
  }
  return out;
}

cv::Mat tile_images(const std::vector<cv::Mat>& images, int columns) {
  if (images.empty()) return {};
  columns = std::clamp(columns, 1, int(images.size()));
  int w = 0, h = 0;
  for (const auto& i : images) w = std::max(w, i.cols), h = std::max(h, i.rows);
  const int rows = (int(images.size()) + columns - 1) / columns;
  cv::Mat out(rows * h, columns * w, CV_8UC3, cv::Scalar(255, 255, 255));
  for (std::size_t k = 0; k < images.size(); ++k) {
    cv::Mat src = images[k];
    if (src.channels() == 1) cv::cvtColor(src, src, cv::COLOR_GRAY2BGR);
    src.copyTo(out(cv::Rect(int(k) % columns * w, int(k) / columns * h, src.cols, src.rows)));
  }
  return out;
}

}  // namespace fleetmap::viz
