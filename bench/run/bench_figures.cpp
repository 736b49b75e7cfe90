// The SVG figures of a `caliber-bench` run, from its results (see bench_figures.h).

#include "bench_figures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "output_file.h"
#include "svg_plot.h"

namespace caliber::cli {
namespace {

using Json = nlohmann::json;
using svg::Axes;
using svg::Canvas;
using svg::Dash;
using svg::Labels;
using svg::LegendEntry;
using svg::Scale;
using svg::Stroke;

/// Each method's colour in every figure.
std::string method_color(const std::string& name) {
  static const std::map<std::string, std::string> colors = {
      {"sequential", "#444444"}, {"exploitation", "#1f77b4"}, {"stealing", "#ff7f0e"},      {"aposteriori", "#2ca02c"},
      {"apriori", "#9467bd"},    {"hybrid", "#d62728"},       {"hybrid+history", "#8c564b"}};
  if (const auto it = colors.find(name); it != colors.end()) return it->second;
  // Any other method: a colour picked by its name, the same in every run.
  static const std::array<const char*, 4> others = {"#17becf", "#bcbd22", "#e377c2", "#7f7f7f"};
  std::size_t sum = 0;
  for (const char c : name) sum += static_cast<unsigned char>(c);
  return others[sum % others.size()];
}

/// printf into a string.
template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

/// A number of the results, or `fallback` when the field is missing or not a number.
double number(const Json& j, const char* key, double fallback) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>() : fallback;
}

/// A list of whole numbers of the results (empty when it is not one).
std::vector<int> ints(const Json& j, const char* key) {
  std::vector<int> v;
  if (!j.contains(key) || !j[key].is_array()) return v;
  for (const Json& x : j[key]) {
    if (x.is_number_integer()) v.push_back(x.get<int>());
  }
  return v;
}

/// One method's speed-ups: measured (thread counts) and simulated (core counts, joined to the last
/// measured point so that the two read as one curve).
struct Curve {
  std::string name;
  std::vector<double> mx, my, sx, sy;
};

Curve curve_of(const std::string& name, const Json& m, const std::vector<int>& threads, const std::vector<int>& simulate,
               double sequential_ms) {
  Curve c{name, {}, {}, {}, {}};
  for (const int t : threads) {
    const std::string key = std::to_string(t);
    if (!m.contains("threads") || !m["threads"].contains(key)) continue;
    const double ms = number(m["threads"][key], "step_ms", 0.0);
    if (ms <= 0.0) continue;
    c.mx.push_back(t);
    c.my.push_back(sequential_ms / ms);
  }
  const Json sim = m.contains("simulated_speedup") ? m["simulated_speedup"] : Json::object();
  for (const int p : simulate) {
    const double speedup = number(sim, std::to_string(p).c_str(), -1.0);
    if (speedup <= 0.0) continue;
    if (c.sx.empty() && !c.mx.empty()) {
      c.sx.push_back(c.mx.back());
      c.sy.push_back(c.my.back());
    }
    c.sx.push_back(p);
    c.sy.push_back(speedup);
  }
  return c;
}

/// speedup_<scene>.svg: speed-up over sequential against threads, log2 on both axes.
std::string speedup_figure(const Json& r, const Json& scene) {
  const std::vector<int> threads = ints(r, "threads"), simulate = ints(r, "simulate");
  const double sequential_ms = number(scene, "sequential_step_ms", 0.0);
  int top = 1;
  for (const int t : threads) top = std::max(top, t);
  for (const int p : simulate) top = std::max(top, p);
  std::vector<Curve> curves;
  std::vector<double> xs = {1.0, static_cast<double>(top)}, ys = xs;
  if (scene.contains("methods") && scene["methods"].is_object()) {
    for (const auto& [name, m] : scene["methods"].items()) {
      if (name == "sequential") continue;
      curves.push_back(curve_of(name, m, threads, simulate, sequential_ms));
      const Curve& c = curves.back();
      xs.insert(xs.end(), c.mx.begin(), c.mx.end());
      xs.insert(xs.end(), c.sx.begin(), c.sx.end());
      ys.insert(ys.end(), c.my.begin(), c.my.end());
      ys.insert(ys.end(), c.sy.begin(), c.sy.end());
    }
  }
  Axes a{64.0, 28.0, 556.0, 352.0, Scale::log2, Scale::log2, svg::padded(xs, Scale::log2), svg::padded(ys, Scale::log2)};
  Canvas canvas(640.0, 425.0);
  const std::string name = scene.value("name", std::string("scene"));
  const int cores = r.value("hardware_threads", 0);
  canvas.axes(a, {format("%s: sequential %.1f ms/step", name.c_str(), sequential_ms),
                  format("threads (measured up to %d, then simulated cores)", cores),
                  "speed-up over sequential",
                  {},
                  13.0});
  const Stroke linear{"#999999", 1.5, Dash::dotted, 0, 1.0};
  canvas.line(a, {1.0, static_cast<double>(top)}, {1.0, static_cast<double>(top)}, linear);
  std::vector<LegendEntry> legend = {{"linear", linear, false}};
  for (const Curve& c : curves) {
    const Stroke measured{method_color(c.name), 1.5, Dash::solid, 'o', 1.0};
    canvas.line(a, c.mx, c.my, measured);
    if (!c.sx.empty()) canvas.line(a, c.sx, c.sy, {measured.color, 1.5, Dash::dashed, 'x', 0.8});
    legend.push_back({c.name + " (measured)", measured, false});
  }
  canvas.legend(a, legend, svg::Corner::upper_left);
  return canvas.str();
}

/// One panel of correlation.svg: a calibrated method's tasks, estimated against effective node
/// tests, on log axes with the diagonal.
struct Panel {
  std::string scene, method;
  const Json* correlation;
};

void correlation_panel(Canvas& canvas, double left, double top, const Panel& p) {
  std::vector<double> xs, ys;
  for (const Json& point : (*p.correlation)["points"]) {
    if (!point.is_array() || point.size() < 2 || !point[0].is_number() || !point[1].is_number()) continue;
    xs.push_back(std::max(point[0].get<double>(), 1e-3));  // clamped: a log axis shows no zero
    ys.push_back(std::max(point[1].get<double>(), 0.5));
  }
  std::vector<double> both = xs;
  both.insert(both.end(), ys.begin(), ys.end());
  const double lo = both.empty() ? 1.0 : *std::min_element(both.begin(), both.end());
  const double hi = both.empty() ? 10.0 : *std::max_element(both.begin(), both.end());
  const svg::Range range = svg::padded({lo, hi}, Scale::log10);
  const Axes a{left + 66.0, top + 26.0, 268.0, 246.0, Scale::log10, Scale::log10, range, range};
  const double pearson = number(*p.correlation, "pearson", NAN);
  const std::string r = std::isfinite(pearson) ? format("%.2f", pearson) : std::string("n/a");
  canvas.axes(a, {p.scene + ", " + p.method + ": r = " + r, "estimated weight", "effective node tests", {}, 11.0});
  canvas.scatter(a, xs, ys, method_color(p.method), 1.5, 0.6);
  canvas.line(a, {lo, hi}, {lo, hi}, {"#999999", 1.5, Dash::dotted, 0, 1.0});
}

/// correlation.svg: one panel per scene and calibrated method with correlation points, up to four
/// to a row (empty when there is none).
std::string correlation_figure(const Json& r) {
  std::vector<Panel> panels;
  if (!r.contains("scenes") || !r["scenes"].is_array()) return {};
  for (const Json& s : r["scenes"]) {
    if (!s.contains("methods") || !s["methods"].is_object()) continue;
    for (const char* name : {"apriori", "hybrid", "hybrid+history"}) {
      if (!s["methods"].contains(name)) continue;
      const Json& m = s["methods"][name];
      if (!m.contains("correlation") || !m["correlation"].is_object()) continue;
      const Json& c = m["correlation"];
      if (c.contains("points") && c["points"].is_array() && !c["points"].empty()) {
        panels.push_back({s.value("name", std::string("scene")), name, &c});
      }
    }
  }
  if (panels.empty()) return {};
  const std::size_t cols = std::min<std::size_t>(4, panels.size()), rows = (panels.size() + cols - 1) / cols;
  Canvas canvas(360.0 * static_cast<double>(cols), 320.0 * static_cast<double>(rows));
  for (std::size_t i = 0; i < panels.size(); ++i) {
    correlation_panel(canvas, 360.0 * static_cast<double>(i % cols), 320.0 * static_cast<double>(i / cols), panels[i]);
  }
  return canvas.str();
}

/// The phases of a timeline, in the legend's order, with their colours and legend labels.
struct Phase {
  const char* name;
  const char* color;
  const char* label;
};
constexpr std::array<Phase, 3> kPhases = {{{"stage", "#9467bd", "weight-driven stage"},
                                           {"traverse", "#1f77b4", "depth-first"},
                                           {"finalize", "#ff7f0e", "finalization"}}};

/// The spans of one method's timeline as bars per phase colour: [start, stop] by the thread's row
/// (a span too short to see widened to `least`).
std::map<std::string, std::vector<std::array<double, 4>>> gantt_bars(const Json& spans, int threads, double least) {
  std::map<std::string, std::vector<std::array<double, 4>>> bars;
  if (!spans.is_array()) return bars;
  for (const Json& sp : spans) {
    if (!sp.is_array() || sp.size() < 4 || !sp[0].is_number_integer() || !sp[1].is_number() || !sp[2].is_number() ||
        !sp[3].is_string()) {
      continue;
    }
    const int thread = sp[0].get<int>();
    if (thread < 0 || thread >= threads) continue;
    const double start = sp[1].get<double>(), stop = sp[2].get<double>();
    std::string color = "#7f7f7f";
    for (const Phase& ph : kPhases) {
      if (sp[3] == ph.name) color = ph.color;
    }
    bars[color].push_back({start, start + std::max(stop - start, least), thread - 0.4, thread + 0.4});
  }
  return bars;
}

/// The latest end of a span in the timeline (at least 1 microsecond).
double gantt_end(const Json& methods) {
  double end = 1e-3;
  for (const auto& [name, m] : methods.items()) {
    if (!m.is_object() || !m.contains("spans") || !m["spans"].is_array()) continue;
    for (const Json& sp : m["spans"]) {
      if (sp.is_array() && sp.size() >= 3 && sp[2].is_number()) end = std::max(end, sp[2].get<double>());
    }
  }
  return end;
}

/// gantt.svg: one step of one scene, a panel per method, a row per thread, x in ms (empty when the
/// results hold no timeline).
std::string gantt_figure(const Json& r) {
  if (!r.contains("gantt") || !r["gantt"].is_object()) return {};
  const Json& g = r["gantt"];
  if (!g.contains("methods") || !g["methods"].is_object() || g["methods"].empty()) return {};
  const int threads = std::clamp(g.value("threads", 1), 1, 1024);
  const double end = gantt_end(g["methods"]), plot_h = 26.0 * threads, block = plot_h + 48.0;
  Canvas canvas(800.0, 24.0 + block * static_cast<double>(g["methods"].size()));
  std::vector<svg::Tick> rows;
  for (int t = 0; t < threads; ++t) rows.push_back({static_cast<double>(t), "thread " + std::to_string(t)});
  std::size_t i = 0;
  for (const auto& [name, m] : g["methods"].items()) {
    Axes a;
    a.left = 70.0;
    a.top = 26.0 + block * static_cast<double>(i);
    a.width = 712.0;
    a.height = plot_h;
    a.x = {0.0, end * 1.02};
    a.y = {-0.5, threads - 0.5};
    a.y_down = true;  // thread 0 on top
    const std::string title =
        format("%s: %s step %d, %d threads, narrow phase %.1f ms", name.c_str(), g.value("scene", std::string("scene")).c_str(),
               g.value("step", 0), threads, number(m, "narrow_ms", 0.0));
    const bool last = ++i == g["methods"].size();
    canvas.axes(a, {title, last ? "ms since the start of the narrow phase" : "", "", rows, 11.0}, false);
    const Json spans = m.is_object() && m.contains("spans") ? m["spans"] : Json::array();
    for (const auto& [color, boxes] : gantt_bars(spans, threads, end * 1e-4)) canvas.bars(a, boxes, color);
    if (i == 1) {
      std::vector<LegendEntry> legend;
      for (const Phase& ph : kPhases) legend.push_back({ph.label, {ph.color, 1.5, Dash::solid, 0, 1.0}, true});
      canvas.legend(a, legend, svg::Corner::upper_right);
    }
  }
  return canvas.str();
}

/// Writes one figure whole, or not at all.
void write_figure(const std::filesystem::path& out, const std::string& name, const std::string& svg) {
  OutputFile file((out / name).string(), name);
  file.stream() << svg;
  file.commit();
}

}  // namespace

std::vector<std::string> write_bench_figures(const Json& results, const std::filesystem::path& out) {
  std::vector<std::string> written;
  if (results.contains("scenes") && results["scenes"].is_array()) {
    for (const Json& s : results["scenes"]) {
      const std::string name = "speedup_" + s.value("name", std::string("scene")) + ".svg";
      write_figure(out, name, speedup_figure(results, s));
      written.push_back(name);
    }
  }
  if (const std::string correlation = correlation_figure(results); !correlation.empty()) {
    write_figure(out, "correlation.svg", correlation);
    written.push_back("correlation.svg");
  }
  if (const std::string gantt = gantt_figure(results); !gantt.empty()) {
    write_figure(out, "gantt.svg", gantt);
    written.push_back("gantt.svg");
  }
  return written;
}

std::vector<std::string> bench_figure_names(const std::vector<std::string>& scene_names) {
  std::vector<std::string> names = {"correlation.svg", "gantt.svg"};
  for (const std::string& s : scene_names) names.push_back("speedup_" + s + ".svg");
  return names;
}

}  // namespace caliber::cli
