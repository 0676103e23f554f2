#include "viz/plot.h"
#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace fleetmap::viz {

namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickFont = 0.45;
constexpr double kLabelFont = 0.5;
constexpr double kTitleFont = 0.6;
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);
const cv::Scalar kWhite(255, 255, 255);

cv::Scalar bgr(const Color& c) { return cv::Scalar(c.b, c.g, c.r); }

bool finite(double v) { return std::isfinite(v); }

int text_width(const std::string& text, double scale) { return cv::getTextSize(text, kFont, scale, 1, nullptr).width; }

void put_text(cv::Mat& img, const std::string& text, cv::Point at, double scale) {
  cv::putText(img, text, at, kFont, scale, kBlack, 1, cv::LINE_AA);
}

void put_centered(cv::Mat& img, const std::string& text, int cx, int baseline_y, double scale) {
  put_text(img, text, cv::Point(cx - text_width(text, scale) / 2, baseline_y), scale);
}

// Text turned 90 degrees counter-clockwise, centred on (cx, cy).
void put_vertical(cv::Mat& img, const std::string& text, int cx, int cy, double scale) {
  if (text.empty()) return;
  int baseline = 0;
  const cv::Size s = cv::getTextSize(text, kFont, scale, 1, &baseline);
  cv::Mat strip(s.height + baseline + 4, s.width + 4, CV_8UC3, kWhite);
  cv::putText(strip, text, cv::Point(2, s.height + 2), kFont, scale, kBlack, 1, cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect where(cx - turned.cols / 2, cy - turned.rows / 2, turned.cols, turned.rows);
  const cv::Rect clipped = where & cv::Rect(0, 0, img.cols, img.rows);
  if (clipped.area() == 0) return;
  turned(cv::Rect(clipped.x - where.x, clipped.y - where.y, clipped.width, clipped.height)).copyTo(img(clipped));
}

// Decimals enough to tell ticks `step` apart.
std::string tick_text(double v, double step) {
  const int decimals = std::clamp(int(-std::floor(std::log10(step) + 1e-9)), 0, 6);
  return fmt::format("{:.{}f}", std::abs(v) < step * 1e-9 ? 0.0 : v, decimals);
}

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
  cv::Point point(double x, double y) const { return cv::Point(int(std::lround(px(x))), int(std::lround(py(y)))); }
};

struct LegendEntry {
  std::string label;
  cv::Scalar color;
  bool box = false;  // a filled square (bars) or a line (series)
};

int legend_width(const std::vector<LegendEntry>& entries) {
  int w = 0;
  for (const auto& e : entries) w = std::max(w, text_width(e.label, kLabelFont));
  return entries.empty() ? 20 : w + 60;
}

void draw_legend(cv::Mat& img, const std::vector<LegendEntry>& entries, int x, int y) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int row = y + int(i) * 22;
    if (entries[i].box) {
      cv::rectangle(img, cv::Rect(x, row - 10, 22, 12), entries[i].color, cv::FILLED);
    } else {
      cv::line(img, cv::Point(x, row - 4), cv::Point(x + 22, row - 4), entries[i].color, 3, cv::LINE_AA);
    }
    put_text(img, entries[i].label, cv::Point(x + 30, row), kLabelFont);
  }
}

// Canvas, title, y ticks with grid lines and y label; returns the frame for the data.
Frame draw_frame(cv::Mat& img, const std::string& title, const std::string& y_label, double y0, double y1,
                 int legend_w, const PlotOptions& options, const std::vector<double>& given_ticks = {}) {
  const auto ticks = given_ticks.empty() ? nice_ticks(y0, y1) : given_ticks;
  int tick_w = 0;
  for (double t : ticks) tick_w = std::max(tick_w, text_width(tick_text(t, tick_step(ticks)), kTickFont));
  const int left = tick_w + 45, top = 45, bottom = 62, right = legend_w + 15;
  img = cv::Mat(options.height_px, options.width_px, CV_8UC3, kWhite);
  Frame f{cv::Rect(left, top, std::max(50, options.width_px - left - right), std::max(50, options.height_px - top - bottom)),
          0.0, 1.0, y0, y1};
  put_centered(img, title, img.cols / 2, 28, kTitleFont);
  for (double t : ticks) {
    if (t < y0 - 1e-9 * (y1 - y0) || t > y1 + 1e-9 * (y1 - y0)) continue;
    const int y = f.area.y + int(std::lround(f.py(t)));
    cv::line(img, cv::Point(f.area.x, y), cv::Point(f.area.x + f.area.width, y), kGrid, 1);
    cv::line(img, cv::Point(f.area.x - 5, y), cv::Point(f.area.x, y), kBlack, 1);
    const std::string text = tick_text(t, tick_step(ticks));
    put_text(img, text, cv::Point(f.area.x - 8 - text_width(text, kTickFont), y + 5), kTickFont);
  }
  put_vertical(img, y_label, 14, f.area.y + f.area.height / 2, kLabelFont);
  return f;
}

void finish_frame(cv::Mat& img, const Frame& f, const std::string& x_label) {
  cv::rectangle(img, f.area, kBlack, 1);
  put_centered(img, x_label, f.area.x + f.area.width / 2, f.area.y + f.area.height + 50, kLabelFont);
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

cv::Mat draw_line_plot(const LinePlot& plot, const PlotOptions& options) {
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
  std::vector<LegendEntry> legend;
  for (const auto& s : plot.series) {
    if (!s.label.empty()) legend.push_back({s.label, bgr(s.color), false});
  }
  cv::Mat img;
  Frame f = draw_frame(img, plot.title, plot.y.label, y0, y1, legend_width(legend), options, plot.y.ticks);
  f.x0 = x0;
  f.x1 = x1;
  const auto xticks = plot.x.ticks.empty() ? nice_ticks(x0, x1, std::max(2, f.area.width / 90)) : plot.x.ticks;
  for (double t : xticks) {
    if (t < x0 || t > x1) continue;
    const int x = f.area.x + int(std::lround(f.px(t)));
    cv::line(img, cv::Point(x, f.area.y), cv::Point(x, f.area.y + f.area.height), kGrid, 1);
    cv::line(img, cv::Point(x, f.area.y + f.area.height), cv::Point(x, f.area.y + f.area.height + 5), kBlack, 1);
    put_centered(img, tick_text(t, tick_step(xticks)), x, f.area.y + f.area.height + 22, kTickFont);
  }

  cv::Mat area = img(f.area);  // drawing here clips to the plot area
  if (plot.bands) {
    cv::Mat overlay = area.clone();
    for (const auto& s : plot.series) {
      if (!has_band(s)) continue;
      for (const auto& [b, e] : runs_of_finite(s)) {
        std::vector<cv::Point> poly;
        for (std::size_t i = b; i < e; ++i) poly.push_back(f.point(s.x[i], s.y_high[i]));
        for (std::size_t i = e; i-- > b;) poly.push_back(f.point(s.x[i], s.y_low[i]));
        cv::fillPoly(overlay, std::vector<std::vector<cv::Point>>{poly}, bgr(s.color), cv::LINE_AA);
      }
    }
    cv::addWeighted(overlay, 0.22, area, 0.78, 0.0, area);
  }
  for (const auto& s : plot.series) {
    for (const auto& [b, e] : runs_of_finite(s)) {
      std::vector<cv::Point> line;
      for (std::size_t i = b; i < e; ++i) line.push_back(f.point(s.x[i], s.y[i]));
      cv::polylines(area, line, false, bgr(s.color), 2, cv::LINE_AA);
      for (std::size_t i = b; i < e; ++i) {
        if (!plot.bands && has_band(s) && finite(s.y_low[i]) && finite(s.y_high[i])) {
          const cv::Point lo = f.point(s.x[i], s.y_low[i]), hi = f.point(s.x[i], s.y_high[i]);
          cv::line(area, lo, hi, bgr(s.color), 1, cv::LINE_AA);
          cv::line(area, lo - cv::Point(4, 0), lo + cv::Point(4, 0), bgr(s.color), 1, cv::LINE_AA);
          cv::line(area, hi - cv::Point(4, 0), hi + cv::Point(4, 0), bgr(s.color), 1, cv::LINE_AA);
        }
        if (s.markers) cv::circle(area, line[i - b], 4, bgr(s.color), cv::FILLED, cv::LINE_AA);
      }
    }
  }
  finish_frame(img, f, plot.x.label);
  draw_legend(img, legend, f.area.x + f.area.width + 15, f.area.y + 14);
  return img;
}

cv::Mat draw_bar_chart(const BarChart& chart, const PlotOptions& options) {
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
    legend.push_back({s < chart.series_labels.size() ? chart.series_labels[s] : "", bgr(c), true});
  }
  cv::Mat img;
  Frame f = draw_frame(img, chart.title, chart.y_label, y0, y1, legend_width(legend), options);
  f.x0 = 0.0;
  f.x1 = double(std::max<std::size_t>(1, n_groups));
  cv::Mat area = img(f.area);
  const double slot = 0.8 / double(std::max<std::size_t>(1, n_series));
  for (std::size_t g = 0; g < n_groups; ++g) {
    for (std::size_t s = 0; s < n_series; ++s) {
      const double v = value(chart.values, s, g);
      if (!finite(v)) continue;
      const double left = double(g) + 0.1 + slot * double(s);
      const cv::Point a = f.point(left + 0.05 * slot, std::max(y0, 0.0)), b = f.point(left + 0.95 * slot, v);
      cv::rectangle(area, cv::Rect(a, b), legend[s].color, cv::FILLED);
      const double lo = value(chart.low, s, g), hi = value(chart.high, s, g);
      if (finite(lo) && finite(hi)) {
        const double mid = left + 0.5 * slot;
        const cv::Point p = f.point(mid, lo), q = f.point(mid, hi);
        cv::line(area, p, q, kBlack, 1, cv::LINE_AA);
        cv::line(area, p - cv::Point(4, 0), p + cv::Point(4, 0), kBlack, 1, cv::LINE_AA);
        cv::line(area, q - cv::Point(4, 0), q + cv::Point(4, 0), kBlack, 1, cv::LINE_AA);
      }
    }
  }
  for (std::size_t g = 0; g < n_groups; ++g) {
    const int cx = f.area.x + int(std::lround(f.px(double(g) + 0.5)));
    const int room = int(f.area.width / double(std::max<std::size_t>(1, n_groups)));
    const double scale = std::min(kLabelFont, kLabelFont * room / double(std::max(1, text_width(chart.groups[g], kLabelFont) + 8)));
    put_centered(img, chart.groups[g], cx, f.area.y + f.area.height + 22, scale);
  }
  finish_frame(img, f, "");
  draw_legend(img, legend, f.area.x + f.area.width + 15, f.area.y + 14);
  return img;
}

cv::Mat tile_images(const std::vector<cv::Mat>& images, int columns) {
  if (images.empty()) return {};
  columns = std::clamp(columns, 1, int(images.size()));
  int w = 0, h = 0;
  for (const auto& i : images) w = std::max(w, i.cols), h = std::max(h, i.rows);
  const int rows = (int(images.size()) + columns - 1) / columns;
  cv::Mat out(rows * h, columns * w, CV_8UC3, kWhite);
  for (std::size_t k = 0; k < images.size(); ++k) {
    cv::Mat src = images[k];
    if (src.channels() == 1) cv::cvtColor(src, src, cv::COLOR_GRAY2BGR);
    src.copyTo(out(cv::Rect(int(k) % columns * w, int(k) / columns * h, src.cols, src.rows)));
  }
  return out;
}

}  // namespace fleetmap::viz
