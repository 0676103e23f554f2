#include "viz/drawing.h"

#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace fleetmap::viz {

namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// SVG font size per unit of Hershey scale: the Hershey simplex capitals are about 21 px tall at
// scale 1, a sans-serif capital about 0.72 of the font size.
constexpr double kSvgFontPerScale = 29.0;

cv::Scalar bgr(const Color& c) { return {double(c.b), double(c.g), double(c.r)}; }
cv::Point rounded(const cv::Point2d& p) { return {int(std::lround(p.x)), int(std::lround(p.y))}; }
int thickness(double width) { return std::max(1, int(std::lround(width))); }

// Runs `draw` on a copy of `region` and blends the copy back with `opacity`.
template <typename Draw>
void blended(cv::Mat region, double opacity, Draw draw) {
  if (opacity >= 1.0) {
    draw(region);
    return;
  }
  cv::Mat overlay = region.clone();
  draw(overlay);
  cv::addWeighted(overlay, opacity, region, 1.0 - opacity, 0.0, region);
}

void raster_text(cv::Mat& img, const Shape& s, cv::Point2d at) {
  const int t = s.bold ? 2 : 1;
  const cv::Size size = text_size(s.text, s.font_scale, s.bold);
  if (s.vertical) {
    int baseline = 0;
    cv::getTextSize(s.text, kFont, s.font_scale, t, &baseline);
    cv::Mat strip(size.height + baseline + 4, size.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(strip, s.text, cv::Point(2, size.height + 2), kFont, s.font_scale, bgr(s.color), t, cv::LINE_AA);
    cv::Mat turned;
    cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
    const cv::Point c = rounded(at);
    const cv::Rect where(c.x - turned.cols / 2, c.y - turned.rows / 2, turned.cols, turned.rows);
    const cv::Rect clipped = where & cv::Rect(0, 0, img.cols, img.rows);
    if (clipped.area() == 0) return;
    // Only the glyphs are copied, so the text does not blank what is under its box.
    cv::Mat src = turned(cv::Rect(clipped.x - where.x, clipped.y - where.y, clipped.width, clipped.height));
    cv::Mat gray, mask;
    cv::cvtColor(src, gray, cv::COLOR_BGR2GRAY);
    cv::threshold(gray, mask, 254, 255, cv::THRESH_BINARY_INV);
    src.copyTo(img(clipped), mask);
    return;
  }
  double x = at.x;
  if (s.anchor == TextAnchor::Middle) x -= size.width / 2.0;
  if (s.anchor == TextAnchor::End) x -= size.width;
  cv::putText(img, s.text, rounded({x, at.y}), kFont, s.font_scale, bgr(s.color), t, cv::LINE_AA);
}

void raster_shape(cv::Mat& img, const Shape& s, cv::Point2d offset) {
  std::vector<cv::Point> pts;
  for (const auto& p : s.points) pts.push_back(rounded(p - offset));
  if (pts.empty()) return;
  switch (s.kind) {
    case Shape::Line:
      blended(img, s.opacity, [&](cv::Mat& target) {
        if (s.dashed) {
          double phase = 0.0;
          for (std::size_t i = 1; i < s.points.size(); ++i) {
            draw_dashed_line(target, s.points[i - 1] - offset, s.points[i] - offset, bgr(s.color), thickness(s.width), phase);
          }
        } else if (pts.size() == 1) {
          cv::circle(target, pts[0], std::max(1, thickness(s.width) / 2), bgr(s.color), cv::FILLED, cv::LINE_AA);
        } else {
          cv::polylines(target, pts, false, bgr(s.color), thickness(s.width), cv::LINE_AA);
        }
      });
      break;
    case Shape::Polygon:
      blended(img, s.opacity, [&](cv::Mat& target) {
        cv::fillPoly(target, std::vector<std::vector<cv::Point>>{pts}, bgr(s.color), cv::LINE_AA);
      });
      if (s.outline) cv::polylines(img, pts, true, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      break;
    case Shape::Circle: {
      if (s.opacity <= 0.0) break;  // a hover spot
      const int r = std::max(1, int(std::lround(s.radius)));
      blended(img, s.opacity, [&](cv::Mat& target) {
        cv::circle(target, pts[0], r, bgr(s.color), s.filled ? cv::FILLED : thickness(s.width), cv::LINE_AA);
      });
      break;
    }
    case Shape::Text: raster_text(img, s, s.points[0] - offset); break;
  }
}

std::string svg_number(double v) {
  std::string s = fmt::format("{:.2f}", v);
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

std::string svg_color(const Color& c) { return fmt::format("rgb({},{},{})", c.r, c.g, c.b); }

std::string escaped(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += ch;
    }
  }
  return out;
}

std::string svg_points(const std::vector<cv::Point2d>& points) {
  std::string out;
  for (const auto& p : points) {
    if (!out.empty()) out += ' ';
    out += svg_number(p.x);
    out += ',';
    out += svg_number(p.y);
  }
  return out;
}

std::string svg_element(const Shape& s);

// The element, with its tooltip as a <title> child.
std::string svg_shape(const Shape& s) {
  std::string e = svg_element(s);
  if (s.tooltip.empty()) return e;
  const std::string title = "<title>" + escaped(s.tooltip) + "</title>";
  if (e.size() >= 3 && e.compare(e.size() - 3, 3, "/>\n") == 0) {
    const std::string tag = e.substr(1, e.find_first_of(" >") - 1);
    return e.substr(0, e.size() - 3) + ">" + title + "</" + tag + ">\n";
  }
  const std::size_t close = e.rfind("</");
  return e.substr(0, close) + title + e.substr(close);
}

std::string svg_element(const Shape& s) {
  std::string attrs;
  if (!s.role.empty()) attrs += " class=\"" + escaped(s.role) + "\"";
  if (s.clip >= 0) attrs += fmt::format(" clip-path=\"url(#clip{})\"", s.clip);
  const auto opacity = [](const char* name, double v) {
    return v < 1.0 ? fmt::format(" {}=\"{}\"", name, svg_number(v)) : std::string();
  };
  switch (s.kind) {
    case Shape::Line:
      return fmt::format(
          "<polyline{} points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"{}{} stroke-linejoin=\"round\" "
          "stroke-linecap=\"{}\"/>\n",
          attrs, svg_points(s.points), svg_color(s.color), svg_number(s.width), opacity("stroke-opacity", s.opacity),
          s.dashed ? fmt::format(" stroke-dasharray=\"{} {}\"", svg_number(4.0 * s.width + 4.0), svg_number(4.0 * s.width + 4.0))
                   : std::string(),
          s.dashed ? "butt" : "round");
    case Shape::Polygon:
      return fmt::format("<polygon{} points=\"{}\" fill=\"{}\"{}{}/>\n", attrs, svg_points(s.points), svg_color(s.color),
                         opacity("fill-opacity", s.opacity), s.outline ? " stroke=\"black\" stroke-width=\"1\"" : "");
    case Shape::Circle:
      return fmt::format("<circle{} cx=\"{}\" cy=\"{}\" r=\"{}\" {}{}/>\n", attrs, svg_number(s.points[0].x),
                         svg_number(s.points[0].y), svg_number(s.radius),
                         s.filled ? "fill=\"" + svg_color(s.color) + "\""
                                  : "fill=\"none\" stroke=\"" + svg_color(s.color) + "\" stroke-width=\"" + svg_number(s.width) + "\"",
                         opacity(s.filled ? "fill-opacity" : "stroke-opacity", s.opacity));
    case Shape::Text: {
      const char* anchor = s.anchor == TextAnchor::Middle ? "middle" : s.anchor == TextAnchor::End ? "end" : "start";
      const std::string x = svg_number(s.points[0].x), y = svg_number(s.points[0].y);
      const std::string placement =
          s.vertical ? fmt::format(" x=\"{}\" y=\"{}\" text-anchor=\"middle\" dominant-baseline=\"central\" transform=\"rotate(-90 {} {})\"", x, y, x, y)
                     : fmt::format(" x=\"{}\" y=\"{}\" text-anchor=\"{}\"", x, y, anchor);
      return fmt::format("<text{}{} font-family=\"Helvetica, Arial, sans-serif\" font-size=\"{}\" fill=\"{}\"{}>{}</text>\n", attrs,
                         placement, svg_number(kSvgFontPerScale * s.font_scale), svg_color(s.color),
                         s.bold ? " font-weight=\"bold\"" : "", escaped(s.text));
    }
  }
  return {};
}

}  // namespace

void Drawing::begin_clip(const cv::Rect& area) {
  clips_.push_back(area);
  clip_ = int(clips_.size()) - 1;
}

Shape& Drawing::add(Shape s) {
  s.clip = clip_;
  shapes_.push_back(std::move(s));
  return shapes_.back();
}

void Drawing::line(cv::Point2d a, cv::Point2d b, const Color& color, double width, bool dashed) {
  polyline({a, b}, color, width, dashed);
}

void Drawing::polyline(std::vector<cv::Point2d> points, const Color& color, double width, bool dashed, double opacity) {
  Shape s;
  s.kind = Shape::Line;
  s.points = std::move(points);
  s.color = color;
  s.width = width;
  s.dashed = dashed;
  s.opacity = opacity;
  add(std::move(s));
}

void Drawing::polygon(std::vector<cv::Point2d> points, const Color& color, double opacity, bool outline) {
  Shape s;
  s.kind = Shape::Polygon;
  s.points = std::move(points);
  s.color = color;
  s.opacity = opacity;
  s.outline = outline;
  add(std::move(s));
}

void Drawing::rect(const cv::Rect2d& r, const Color& color, double opacity, bool outline) {
  polygon({r.tl(), {r.x + r.width, r.y}, r.br(), {r.x, r.y + r.height}}, color, opacity, outline);
}

void Drawing::hover_spot(cv::Point2d centre, double radius, std::string text) {
  circle(centre, radius, Color{}, true);
  shapes_.back().opacity = 0.0;
  shapes_.back().role = "tip";
  shapes_.back().tooltip = std::move(text);
}

void Drawing::circle(cv::Point2d centre, double radius, const Color& color, bool filled, double width) {
  Shape s;
  s.kind = Shape::Circle;
  s.points = {centre};
  s.radius = radius;
  s.color = color;
  s.filled = filled;
  s.width = width;
  add(std::move(s));
}

void Drawing::text(cv::Point2d at, std::string text, double font_scale, TextAnchor anchor, bool bold, const Color& color) {
  if (text.empty()) return;
  Shape s;
  s.kind = Shape::Text;
  s.points = {at};
  s.text = std::move(text);
  s.font_scale = font_scale;
  s.anchor = anchor;
  s.bold = bold;
  s.color = color;
  add(std::move(s));
}

void Drawing::vertical_text(cv::Point2d centre, std::string text, double font_scale) {
  if (text.empty()) return;
  Shape s;
  s.kind = Shape::Text;
  s.points = {centre};
  s.text = std::move(text);
  s.font_scale = font_scale;
  s.vertical = true;
  add(std::move(s));
}

void Drawing::place(const Drawing& other, cv::Point2d offset) {
  const int first_clip = int(clips_.size());
  for (const auto& c : other.clips_) clips_.push_back(c + cv::Point(int(std::lround(offset.x)), int(std::lround(offset.y))));
  for (Shape s : other.shapes_) {
    for (auto& p : s.points) p += offset;
    if (s.clip >= 0) s.clip += first_clip;
    shapes_.push_back(std::move(s));
  }
}

cv::Size text_size(const std::string& text, double font_scale, bool bold) {
  return cv::getTextSize(text, kFont, font_scale, bold ? 2 : 1, nullptr);
}

cv::Mat rasterize(const Drawing& drawing) {
  if (drawing.empty()) return {};
  cv::Mat img(drawing.height(), drawing.width(), CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect all(0, 0, img.cols, img.rows);
  for (const auto& s : drawing.shapes()) {
    if (s.clip < 0) {
      raster_shape(img, s, {0.0, 0.0});
      continue;
    }
    const cv::Rect area = drawing.clips()[std::size_t(s.clip)] & all;
    if (area.area() == 0) continue;
    cv::Mat region = img(area);
    raster_shape(region, s, cv::Point2d(area.x, area.y));
  }
  return img;
}

std::string to_svg(const Drawing& drawing) {
  std::string svg = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\">\n",
      drawing.width(), drawing.height(), drawing.width(), drawing.height());
  if (!drawing.clips().empty()) {
    svg += "<defs>\n";
    for (std::size_t i = 0; i < drawing.clips().size(); ++i) {
      const auto& c = drawing.clips()[i];
      svg += fmt::format("<clipPath id=\"clip{}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n", i, c.x,
                         c.y, c.width, c.height);
    }
    svg += "</defs>\n";
  }
  svg += fmt::format("<rect width=\"{}\" height=\"{}\" fill=\"white\"/>\n", drawing.width(), drawing.height());
  for (const auto& s : drawing.shapes()) svg += svg_shape(s);
  return svg + "</svg>\n";
}

void draw_dashed_line(cv::Mat& img, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, int thickness, double& phase) {
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

}  // namespace fleetmap::viz
