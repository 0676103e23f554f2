#pragma once
// A figure as a list of vector shapes in pixel coordinates (x right, y down): lines, filled
// polygons with an opacity, discs, text. The same list is drawn as a raster image (OpenCV) and
// written as SVG, so a plot's PNG and its SVG show the same figure, the SVG for papers.
#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

#include "viz/render.h"

namespace fleetmap::viz {

enum class TextAnchor { Start, Middle, End };

struct Shape {
  enum Kind { Line, Polygon, Circle, Text } kind = Line;
  std::vector<cv::Point2d> points;  // Line: the polyline; Polygon: the outline; Circle, Text: one point
  Color color;
  double opacity = 1.0;  // of the fill (Polygon, Circle) or of the stroke (Line)
  double width = 1.0;    // stroke width in pixels (Line; Polygon and Circle outlines when > 0 and `outline`)
  bool dashed = false;   // Line
  bool filled = true;    // Circle: a disc, or a ring of `width`
  bool outline = false;  // Polygon: also stroke the outline in black
  double radius = 0.0;   // Circle
  std::string text;      // Text; `points[0]` is the baseline point at the anchor
  double font_scale = 0.5;  // OpenCV's Hershey scale; the SVG's font size follows it
  TextAnchor anchor = TextAnchor::Start;
  bool vertical = false;  // Text turned 90 degrees counter-clockwise, centred on the point
  bool bold = false;
  int clip = -1;  // index into Drawing::clips, or -1
  std::string role;  // e.g. "series", "band": the SVG element's class, for readers and editors
  std::string tooltip;  // the SVG element's <title>: what a browser shows when the pointer rests on it
};

class Drawing {
 public:
  Drawing() = default;
  Drawing(int width, int height) : width_(width), height_(height) {}

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ <= 0 || height_ <= 0; }
  const std::vector<Shape>& shapes() const { return shapes_; }
  const std::vector<cv::Rect>& clips() const { return clips_; }

  // Shapes added until end_clip() are cut to `area`.
  void begin_clip(const cv::Rect& area);
  void end_clip() { clip_ = -1; }

  void line(cv::Point2d a, cv::Point2d b, const Color& color, double width = 1.0, bool dashed = false);
  void polyline(std::vector<cv::Point2d> points, const Color& color, double width = 1.0, bool dashed = false,
                double opacity = 1.0);
  void polygon(std::vector<cv::Point2d> points, const Color& color, double opacity = 1.0, bool outline = false);
  void rect(const cv::Rect2d& r, const Color& color, double opacity = 1.0, bool outline = false);
  void circle(cv::Point2d centre, double radius, const Color& color, bool filled = true, double width = 1.0);
  void text(cv::Point2d at, std::string text, double font_scale, TextAnchor anchor = TextAnchor::Start,
            bool bold = false, const Color& color = {});
  void vertical_text(cv::Point2d centre, std::string text, double font_scale);

  // The role of the most recently added shape (see Shape::role).
  void set_role(std::string role) { if (!shapes_.empty()) shapes_.back().role = std::move(role); }
  // The tooltip of the most recently added shape (see Shape::tooltip).
  void set_tooltip(std::string text) { if (!shapes_.empty()) shapes_.back().tooltip = std::move(text); }
  // An invisible disc that only carries a tooltip (SVG); the raster shows nothing of it.
  void hover_spot(cv::Point2d centre, double radius, std::string text);

  // Copies `other`'s shapes shifted by `offset` (its clips too), e.g. panels side by side.
  void place(const Drawing& other, cv::Point2d offset);

 private:
  Shape& add(Shape s);
  int width_ = 0, height_ = 0;
  std::vector<Shape> shapes_;
  std::vector<cv::Rect> clips_;
  int clip_ = -1;
};

// The width and height in pixels of `text` as the raster draws it (OpenCV's Hershey simplex font).
cv::Size text_size(const std::string& text, double font_scale, bool bold = false);

// The drawing on a white BGR image of its size; translucent shapes blend with what is under them.
cv::Mat rasterize(const Drawing& drawing);
// The drawing as a standalone SVG document, one element per shape (a shape's `role` becomes its
// class attribute, e.g. class="series" on each plotted line).
std::string to_svg(const Drawing& drawing);

// A dashed line on a raster image; `phase` carries the dash pattern from one segment to the next.
void draw_dashed_line(cv::Mat& image, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, int thickness,
                      double& phase);

}  // namespace fleetmap::viz
