#pragma once
// A small SVG plotter for caliber-bench's figures: axes with linear, log2 or log10 scales, their
// ticks, grid and labels; lines (solid, dashed, dotted) with circle or cross markers; scatter
// points; horizontal bars; titles and legends. Every coordinate is written rounded (to 0.1 px, a
// scatter point to the pixel) and every choice depends on the data alone, so the same data always
// gives the same bytes.

#include <array>
#include <sstream>
#include <string>
#include <vector>

namespace caliber::cli::svg {

enum class Scale { linear, log2, log10 };

/// A data interval on one axis.
struct Range {
  double lo = 0.0;
  double hi = 1.0;
};

/// The interval spanned by `values` (the positive ones on a log scale), widened by `margin` of its
/// width on each side (in log space on a log scale); a single value gets a width of its own.
[[nodiscard]] Range padded(const std::vector<double>& values, Scale scale, double margin = 0.05);

/// A tick: where it stands on its axis and its label.
struct Tick {
  double value = 0.0;
  std::string label;
};

/// The ticks of an axis: powers of two on a log2 scale (1, 2, 4, ...), powers of ten on a log10
/// scale (0.1, 1, 10, ...; with 2 and 5 times them when fewer than two powers fall in the range),
/// round steps on a linear scale.
[[nodiscard]] std::vector<Tick> ticks(Scale scale, Range range);

/// A number as SVG text: rounded to 0.1, without a trailing ".0" or a "-0".
[[nodiscard]] std::string num(double v);

/// Text with XML's special characters escaped.
[[nodiscard]] std::string escape(const std::string& text);

enum class Dash { solid, dashed, dotted };

/// How a line and its markers are drawn.
struct Stroke {
  std::string color = "#000000";
  double width = 1.5;
  Dash dash = Dash::solid;
  char marker = 0;  ///< 0: none, 'o': a filled circle, 'x': a cross
  double opacity = 1.0;
};

/// One legend entry: a line (with its marker), or a filled box of the stroke's colour.
struct LegendEntry {
  std::string label;
  Stroke stroke;
  bool box = false;
};

enum class Corner { upper_left, upper_right };

/// A set of axes: the plot area on the canvas (px) and the data range it shows.
struct Axes {
  double left = 0.0;
  double top = 0.0;
  double width = 100.0;
  double height = 100.0;
  Scale xscale = Scale::linear;
  Scale yscale = Scale::linear;
  Range x;
  Range y;
  bool y_down = false;  ///< y grows downwards (rows listed from the top)

  /// The canvas position of a data value on each axis.
  [[nodiscard]] double px(double v) const;
  [[nodiscard]] double py(double v) const;
};

/// The text around a set of axes; `yticks`, when given, replaces the y scale's own ticks.
struct Labels {
  std::string title;
  std::string xlabel;
  std::string ylabel;
  std::vector<Tick> yticks;
  double title_size = 12.0;
};

/// An SVG document being drawn: a white page of the given size in px, sans-serif text.
class Canvas {
 public:
  Canvas(double width, double height);

  /// The axes' grid (at the ticks, when `grid`), frame, ticks, tick labels, title and axis labels.
  void axes(const Axes& a, const Labels& labels, bool grid = true);
  /// A polyline through the points (those a log scale cannot show left out), with its markers.
  void line(const Axes& a, const std::vector<double>& xs, const std::vector<double>& ys, const Stroke& s);
  /// Dots of `radius` px, drawn as one path at whole pixels; points on the same pixel are drawn once.
  void scatter(const Axes& a, const std::vector<double>& xs, const std::vector<double>& ys, const std::string& color,
               double radius, double opacity);
  /// Filled boxes {x0, x1, y0, y1} in data units, as one path with a thin white edge.
  void bars(const Axes& a, const std::vector<std::array<double, 4>>& boxes, const std::string& color);
  /// A legend in a corner of the axes.
  void legend(const Axes& a, const std::vector<LegendEntry>& entries, Corner corner);
  /// Text at (x, y) px; `anchor` is start, middle or end; `rotate` in degrees.
  void text(double x, double y, const std::string& s, double size, const char* anchor, double rotate = 0.0);

  /// The whole document.
  [[nodiscard]] std::string str() const;

 private:
  void markers(const std::vector<std::array<double, 2>>& points, const Stroke& s);
  double mWidth;
  double mHeight;
  std::ostringstream mBody;
};

}  // namespace caliber::cli::svg
