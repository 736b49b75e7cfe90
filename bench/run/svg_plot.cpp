// A small SVG plotter for caliber-bench's figures (see svg_plot.h).

#include "svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

namespace caliber::cli::svg {
namespace {

/// The value on the axis's own straight scale: itself, or its logarithm.
double forward(Scale s, double v) {
  if (s == Scale::log2) return std::log2(v);
  if (s == Scale::log10) return std::log10(v);
  return v;
}

double inverse(Scale s, double v) {
  if (s == Scale::log2) return std::exp2(v);
  if (s == Scale::log10) return std::pow(10.0, v);
  return v;
}

/// Whether a scale can show the value (a log scale: positive values only).
bool shown(Scale s, double v) { return std::isfinite(v) && (s == Scale::linear || v > 0.0); }

/// A tick value as a label: whole numbers in full, others in %g.
std::string value_label(double v) {
  char buf[40];
  if (v == std::floor(v) && std::fabs(v) < 1e7) {
    std::snprintf(buf, sizeof buf, "%.0f", v == 0.0 ? 0.0 : v);
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}

/// Whether v lies in the range, give or take a rounding error.
bool inside(Range r, double v) {
  const double slack = 1e-9 * std::max(std::fabs(r.lo), std::fabs(r.hi));
  return v >= r.lo - slack && v <= r.hi + slack;
}

/// Every `stride`-th tick, so that no axis gets more than `most` labels.
std::vector<Tick> thinned(std::vector<Tick> t, std::size_t most) {
  if (t.size() <= most) return t;
  const std::size_t stride = (t.size() + most - 1) / most;
  std::vector<Tick> kept;
  for (std::size_t i = 0; i < t.size(); i += stride) kept.push_back(t[i]);
  return kept;
}

/// Powers of `base` in the range, times each of `multiples`.
std::vector<Tick> log_ticks(Range r, double base, const std::vector<double>& multiples) {
  std::vector<Tick> t;
  const double k0 = std::floor(std::log(r.lo) / std::log(base)) - 1.0;
  const double k1 = std::ceil(std::log(r.hi) / std::log(base)) + 1.0;
  for (double k = k0; k <= k1; k += 1.0) {
    for (const double m : multiples) {
      const double v = m * std::pow(base, k);
      if (inside(r, v)) t.push_back({v, value_label(v)});
    }
  }
  return t;
}

/// Steps of 1, 2 or 5 times a power of ten, about six of them across the range.
std::vector<Tick> linear_ticks(Range r) {
  const double raw = (r.hi - r.lo) / 6.0;
  if (!(raw > 0.0) || !std::isfinite(raw)) return {{r.lo, value_label(r.lo)}};
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double step = (norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0) * mag;
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  std::vector<Tick> t;
  for (double i = std::ceil(r.lo / step - 1e-9); i * step <= r.hi + 1e-9 * step; i += 1.0) {
    const double v = i * step;
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v == 0.0 ? 0.0 : v);
    t.push_back({v, buf});
  }
  return t;
}

/// The longest label of a set of ticks, in characters.
std::size_t longest(const std::vector<Tick>& t) {
  std::size_t n = 0;
  for (const Tick& k : t) n = std::max(n, k.label.size());
  return n;
}

/// The attributes of a stroke: colour, width, dashes, opacity.
std::string stroke_attributes(const Stroke& s) {
  std::string a = " stroke=\"" + s.color + "\" stroke-width=\"" + num(s.width) + "\"";
  if (s.dash == Dash::dashed) a += " stroke-dasharray=\"" + num(3.7 * s.width) + " " + num(1.6 * s.width) + "\"";
  if (s.dash == Dash::dotted) a += " stroke-dasharray=\"" + num(s.width) + " " + num(1.65 * s.width) + "\"";
  if (s.opacity < 1.0) a += " stroke-opacity=\"" + num(s.opacity) + "\"";
  return a;
}

}  // namespace

std::string num(double v) {
  char buf[40];
  const double r = std::round(v * 10.0) / 10.0;
  std::snprintf(buf, sizeof buf, "%.1f", r == 0.0 ? 0.0 : r);
  std::string s = buf;
  if (s.size() > 2 && s.compare(s.size() - 2, 2, ".0") == 0) s.resize(s.size() - 2);
  return s;
}

std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += static_cast<unsigned char>(c) < 0x20 ? ' ' : c;  // XML 1.0 allows no control characters
    }
  }
  return out;
}

Range padded(const std::vector<double>& values, Scale scale, double margin) {
  std::vector<double> v;
  for (const double x : values) {
    if (shown(scale, x)) v.push_back(forward(scale, x));
  }
  if (v.empty()) return scale == Scale::linear ? Range{0.0, 1.0} : Range{1.0, scale == Scale::log2 ? 2.0 : 10.0};
  double lo = *std::min_element(v.begin(), v.end());
  double hi = *std::max_element(v.begin(), v.end());
  if (hi - lo <= 1e-12 * std::max(1.0, std::fabs(lo))) {
    const double d = scale == Scale::linear ? std::max(0.5, 0.5 * std::fabs(lo)) : 1.0;
    lo -= d;
    hi += d;
  } else {
    const double pad = (hi - lo) * margin;
    lo -= pad;
    hi += pad;
  }
  return {inverse(scale, lo), inverse(scale, hi)};
}

std::vector<Tick> ticks(Scale scale, Range range) {
  if (scale == Scale::linear) return thinned(linear_ticks(range), 12);
  if (scale == Scale::log2) return thinned(log_ticks(range, 2.0, {1.0}), 12);
  std::vector<Tick> t = log_ticks(range, 10.0, {1.0});
  if (t.size() < 2) t = log_ticks(range, 10.0, {1.0, 2.0, 5.0});
  if (t.size() < 2) t = log_ticks(range, 10.0, {1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0});
  return thinned(t, 10);
}

double Axes::px(double v) const {
  const double f0 = forward(xscale, x.lo), f1 = forward(xscale, x.hi);
  return left + (forward(xscale, v) - f0) / (f1 - f0) * width;
}

double Axes::py(double v) const {
  const double f0 = forward(yscale, y.lo), f1 = forward(yscale, y.hi);
  const double t = (forward(yscale, v) - f0) / (f1 - f0);
  return y_down ? top + t * height : top + height - t * height;
}

Canvas::Canvas(double width, double height) : mWidth(width), mHeight(height) {}

void Canvas::axes(const Axes& a, const Labels& labels, bool grid) {
  const std::vector<Tick> xt = ticks(a.xscale, a.x);
  const std::vector<Tick> yt = labels.yticks.empty() ? ticks(a.yscale, a.y) : labels.yticks;
  const double right = a.left + a.width, bottom = a.top + a.height;
  std::ostringstream grid_d, tick_d;
  for (const Tick& t : xt) {
    grid_d << "M" << num(a.px(t.value)) << " " << num(a.top) << "V" << num(bottom);
    tick_d << "M" << num(a.px(t.value)) << " " << num(bottom) << "v3.5";
  }
  for (const Tick& t : yt) {
    grid_d << "M" << num(a.left) << " " << num(a.py(t.value)) << "H" << num(right);
    tick_d << "M" << num(a.left) << " " << num(a.py(t.value)) << "h-3.5";
  }
  if (grid && !grid_d.str().empty()) mBody << "<path d=\"" << grid_d.str() << "\" stroke=\"#dedede\" stroke-width=\"0.8\"/>\n";
  mBody << "<rect x=\"" << num(a.left) << "\" y=\"" << num(a.top) << "\" width=\"" << num(a.width) << "\" height=\""
        << num(a.height) << "\" fill=\"none\" stroke=\"#000\" stroke-width=\"0.8\"/>\n";
  if (!tick_d.str().empty()) mBody << "<path d=\"" << tick_d.str() << "\" stroke=\"#000\" stroke-width=\"0.8\"/>\n";
  for (const Tick& t : xt) text(a.px(t.value), bottom + 14.0, t.label, 10.0, "middle");
  for (const Tick& t : yt) text(a.left - 6.0, a.py(t.value) + 3.5, t.label, 10.0, "end");
  if (!labels.title.empty()) text(a.left + a.width / 2.0, a.top - 8.0, labels.title, labels.title_size, "middle");
  if (!labels.xlabel.empty()) text(a.left + a.width / 2.0, bottom + 32.0, labels.xlabel, 11.0, "middle");
  if (!labels.ylabel.empty()) {
    const double x = a.left - 14.0 - 5.6 * static_cast<double>(longest(yt));
    text(x, a.top + a.height / 2.0, labels.ylabel, 11.0, "middle", -90.0);
  }
}

void Canvas::line(const Axes& a, const std::vector<double>& xs, const std::vector<double>& ys, const Stroke& s) {
  std::vector<std::array<double, 2>> points;
  for (std::size_t i = 0; i < xs.size() && i < ys.size(); ++i) {
    if (shown(a.xscale, xs[i]) && shown(a.yscale, ys[i])) points.push_back({a.px(xs[i]), a.py(ys[i])});
  }
  if (points.size() >= 2) {
    mBody << "<polyline points=\"";
    for (std::size_t i = 0; i < points.size(); ++i) mBody << (i ? " " : "") << num(points[i][0]) << "," << num(points[i][1]);
    mBody << "\" fill=\"none\"" << stroke_attributes(s) << " stroke-linejoin=\"round\"/>\n";
  }
  markers(points, s);
}

void Canvas::markers(const std::vector<std::array<double, 2>>& points, const Stroke& s) {
  if (s.marker == 'o') {
    for (const auto& p : points) {
      mBody << "<circle cx=\"" << num(p[0]) << "\" cy=\"" << num(p[1]) << "\" r=\"2.7\" fill=\"" << s.color << "\""
            << (s.opacity < 1.0 ? " fill-opacity=\"" + num(s.opacity) + "\"" : std::string()) << "/>\n";
    }
  } else if (s.marker == 'x' && !points.empty()) {
    mBody << "<path d=\"";
    for (const auto& p : points) mBody << "M" << num(p[0] - 2.5) << " " << num(p[1] - 2.5) << "l5 5m0 -5l-5 5";
    mBody << "\" stroke=\"" << s.color << "\" stroke-width=\"1.1\"";
    if (s.opacity < 1.0) mBody << " stroke-opacity=\"" << num(s.opacity) << "\"";
    mBody << "/>\n";
  }
}

void Canvas::scatter(const Axes& a, const std::vector<double>& xs, const std::vector<double>& ys, const std::string& color,
                     double radius, double opacity) {
  std::set<std::pair<long, long>> seen;
  std::ostringstream d;
  for (std::size_t i = 0; i < xs.size() && i < ys.size(); ++i) {
    if (!shown(a.xscale, xs[i]) || !shown(a.yscale, ys[i])) continue;
    const long x = std::lround(a.px(xs[i]) - a.left), y = std::lround(a.py(ys[i]) - a.top);
    if (!seen.insert({x, y}).second) continue;
    d << "M" << x << " " << y << "h0";
  }
  if (seen.empty()) return;
  mBody << "<path transform=\"translate(" << num(a.left) << "," << num(a.top) << ")\" d=\"" << d.str() << "\" stroke=\"" << color
        << "\" stroke-width=\"" << num(2.0 * radius) << "\" stroke-linecap=\"round\" stroke-opacity=\"" << num(opacity)
        << "\"/>\n";
}

void Canvas::bars(const Axes& a, const std::vector<std::array<double, 4>>& boxes, const std::string& color) {
  if (boxes.empty()) return;
  mBody << "<path d=\"";
  for (const auto& b : boxes) {
    const double x0 = a.px(b[0]), x1 = a.px(b[1]), y0 = a.py(b[2]), y1 = a.py(b[3]);
    const double x = std::min(x0, x1), y = std::min(y0, y1);
    mBody << "M" << num(x) << " " << num(y) << "h" << num(std::fabs(x1 - x0)) << "v" << num(std::fabs(y1 - y0)) << "h"
          << num(-std::fabs(x1 - x0)) << "z";
  }
  mBody << "\" fill=\"" << color << "\" stroke=\"#fff\" stroke-width=\"0.3\"/>\n";
}

void Canvas::legend(const Axes& a, const std::vector<LegendEntry>& entries, Corner corner) {
  if (entries.empty()) return;
  std::size_t chars = 0;
  for (const LegendEntry& e : entries) chars = std::max(chars, e.label.size());
  const double w = 40.0 + 5.0 * static_cast<double>(chars), h = 8.0 + 13.0 * static_cast<double>(entries.size());
  const double x = corner == Corner::upper_left ? a.left + 6.0 : a.left + a.width - 6.0 - w, y = a.top + 6.0;
  mBody << "<rect x=\"" << num(x) << "\" y=\"" << num(y) << "\" width=\"" << num(w) << "\" height=\"" << num(h)
        << "\" rx=\"2\" fill=\"#fff\" fill-opacity=\"0.85\" stroke=\"#ccc\" stroke-width=\"0.8\"/>\n";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const double yc = y + 10.5 + 13.0 * static_cast<double>(i);
    if (e.box) {
      mBody << "<rect x=\"" << num(x + 6.0) << "\" y=\"" << num(yc - 4.0) << "\" width=\"20\" height=\"8\" fill=\""
            << e.stroke.color << "\"/>\n";
    } else {
      mBody << "<path d=\"M" << num(x + 6.0) << " " << num(yc) << "h20\" fill=\"none\"" << stroke_attributes(e.stroke) << "/>\n";
      markers({{x + 16.0, yc}}, e.stroke);
    }
    text(x + 32.0, yc + 3.0, e.label, 9.0, "start");
  }
}

void Canvas::text(double x, double y, const std::string& s, double size, const char* anchor, double rotate) {
  mBody << "<text x=\"" << num(x) << "\" y=\"" << num(y) << "\" font-size=\"" << num(size) << "\"";
  if (std::string(anchor) != "start") mBody << " text-anchor=\"" << anchor << "\"";
  if (rotate != 0.0) mBody << " transform=\"rotate(" << num(rotate) << " " << num(x) << " " << num(y) << ")\"";
  mBody << ">" << escape(s) << "</text>\n";
}

std::string Canvas::str() const {
  const std::string w = num(mWidth), h = num(mHeight);
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + w + "\" height=\"" +
         h + "\" viewBox=\"0 0 " + w + " " + h + "\" font-family=\"sans-serif\">\n<rect width=\"" + w + "\" height=\"" + h +
         "\" fill=\"#fff\"/>\n" + mBody.str() + "</svg>\n";
}

}  // namespace caliber::cli::svg
