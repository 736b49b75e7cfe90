// report.md of `caliber-bench`, written from its results.json: every figure in it is measured
// (or simulated, and said so) in that run.

#include "bench_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "output_file.h"
#include "timing.h"
#include "caliber/error.h"

namespace caliber::cli {
namespace {

using Json = nlohmann::json;

std::string num(double x, const char* format = "%.2f") {
  char b[64];
  std::snprintf(b, sizeof b, format, x);
  return b;
}

/// Step time (ms) of a method at t threads in a scene, or NaN if not measured.
double step_ms(const Json& scene, const std::string& method, int t) {
  const Json& m = scene["methods"];
  if (!m.contains(method) || !m[method]["threads"].contains(std::to_string(t))) return std::nan("");
  return m[method]["threads"][std::to_string(t)]["step_ms"].get<double>();
}

double phase_ms(const Json& scene, const std::string& method, int t, const char* phase) {
  const Json& m = scene["methods"];
  if (!m.contains(method) || !m[method]["threads"].contains(std::to_string(t))) return std::nan("");
  const Json& p = m[method]["threads"][std::to_string(t)]["phases_per_step"];
  return p.contains(phase) ? p[phase].get<double>() : std::nan("");
}

std::vector<std::string> method_names(const Json& scene) {
  std::vector<std::string> names;
  for (const auto& [name, value] : scene["methods"].items()) names.push_back(name);
  // Keep the paper's order: sequential, exploitation, stealing, aposteriori, apriori, hybrid(+history).
  const std::vector<std::string> order = {"sequential", "exploitation", "stealing",      "aposteriori",
                                          "apriori",    "hybrid",       "hybrid+history"};
  std::vector<std::string> sorted;
  for (const std::string& o : order) {
    if (std::find(names.begin(), names.end(), o) != names.end()) sorted.push_back(o);
  }
  return sorted;
}

}  // namespace

void write_bench_report(const Json& r, const std::filesystem::path& file) {
  cli::OutputFile output(file.string(), "report.md");  // written whole, or not at all
  std::ostream& out = output.stream();
  const std::vector<int> threads = r["threads"].get<std::vector<int>>();
  const std::vector<int> simulate = r["simulate"].get<std::vector<int>>();
  const int cores = r["hardware_threads"].get<int>();
  const int max_t = threads.back();

  out << "# caliber-bench\n\n";
  out << "Machine: " << r["machine"].get<std::string>() << ".\n\n";
  out << "Each configuration ran " << r["repeat"].get<int>() << " time(s), in interleaved rounds (round r runs every "
      << "configuration once, so that a slow spell of a shared machine does not land on one configuration); times are "
      << "medians of the whole run, per step "
      << "(broad phase + narrow phase + reduction). Speed-ups are over `sequential` on the same machine. Every run's "
      << "contacts were compared with `sequential`'s at every step: "
      << (r["contacts_identical"].get<bool>() ? "**all identical**" : "**MISMATCHES (see the program's output)**") << ".\n\n";
  if (r.contains("runs_done") && r.contains("runs_planned")) {
    out << "Runs done: " << r["runs_done"] << " of " << r["runs_planned"] << " planned";
    if (r.contains("stopped")) {
      out << (r["stopped"]["reason"] == "interrupted"
                  ? "; **interrupted** (" + r["stopped"].value("signal", std::string("a signal")) + ")"
                  : std::string("; **cut short by its time budget** (`--budget-s`)"))
          << " after " << num(r["stopped"]["after_s"].get<double>(), "%.0f")
          << " s: this report covers what ran, and a configuration missing below was not measured";
    } else if (r["runs_done"].get<std::size_t>() < r["runs_planned"].get<std::size_t>()) {
      out << "; **the log ends before the run did** (killed, or cut by a time limit): this report covers the runs it holds";
    }
    out << ".\n\n";
  }
  if (r["scenes"].empty()) {
    out << "No scene finished its sequential reference run: nothing to report yet.\n";
    output.commit();
    return;
  }
  out << "Real (measured) figures stop at this machine's " << cores << " hardware thread(s); the columns P = ";
  for (std::size_t i = 0; i < simulate.size(); ++i) out << (i ? ", " : "") << simulate[i];
  out << " are the **load-balance simulation** (node tests of the run-time tasks, cut for P threads, list-scheduled on P "
         "virtual cores; "
      << (r["simulate_steps"].get<int>() > 0 ? "first " + std::to_string(r["simulate_steps"].get<int>()) + " steps"
                                             : std::string("every step"))
      << "), not measurements.\n\n";

  out << "## Table 1: scenes\n\n| scene | objects | triangles | node tests / step | contacts / step | pairs / step | "
         "candidate pairs | heaviest pair | second | exploitation bound | sequential ms / step "
         "|\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    const Json& t = s["table1"];
    out << "| " << s["name"].get<std::string>() << " | " << t["objects"] << " | " << t["triangles"] << " | "
        << num(t["node_tests_per_step"].get<double>(), "%.0f") << " | " << num(t["contacts_per_step"].get<double>(), "%.1f")
        << " | " << num(t["pairs_per_step"].get<double>(), "%.1f") << " | " << t["candidate_pairs"] << " | "
        << num(100 * t["heaviest_pair_share"].get<double>(), "%.1f") << " % | "
        << num(100 * t["second_pair_share"].get<double>(), "%.1f") << " % | " << num(t["exploitation_bound"].get<double>())
        << "x | " << num(s["sequential_step_ms"].get<double>()) << " |\n";
  }

  out << "\n## Table 2: time per step (ms) and speed-up over sequential\n\n| scene | method |";
  for (const int t : threads) out << " " << t << " thread" << (t > 1 ? "s" : "") << " |";
  out << "\n|---|---|";
  for (std::size_t i = 0; i < threads.size(); ++i) out << "---|";
  out << "\n";
  for (const Json& s : r["scenes"]) {
    const double seq = s["sequential_step_ms"].get<double>();
    for (const std::string& m : method_names(s)) {
      out << "| " << s["name"].get<std::string>() << " | " << m << " |";
      for (const int t : threads) {
        const double ms = step_ms(s, m, t);
        out << " " << (std::isnan(ms) ? "" : num(ms) + " (" + num(seq / ms) + "x)") << " |";
      }
      out << "\n";
    }
  }

  out << "\n## The machine's ceiling\n\nP independent sequential copies of the scene run at once (each its own world and "
         "engine, nothing shared): the ceiling is P x (one copy alone) / (each copy among P), what memory, shared caches and "
         "clock boost leave of P x before any scheduling. Measured, not simulated. Each method's speed-up is also given as a "
         "fraction of it.\n\n| scene | P | one copy alone (ms/step) | each of P copies (median ms/step) | ceiling | best method "
         "at P "
         "| its speed-up | of the ceiling |\n|---|---|---|---|---|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    if (!s.contains("ceiling")) continue;
    const double seq = s["sequential_step_ms"].get<double>();
    for (const auto& [p, c] : s["ceiling"].items()) {
      const int t = std::stoi(p);
      std::string best;
      double best_sp = std::nan("");
      for (const std::string& m : method_names(s)) {
        const double sp = seq / step_ms(s, m, t);
        if (m != "sequential" && !std::isnan(sp) && (std::isnan(best_sp) || sp > best_sp)) {
          best = m;
          best_sp = sp;
        }
      }
      const double ceiling = c["ceiling_speedup"].get<double>();
      out << "| " << s["name"].get<std::string>() << " | " << p << " | " << num(seq) << " | "
          << num(median_of(c["copy_step_ms"].get<std::vector<double>>())) << " | " << num(ceiling) << "x | " << best << " | "
          << (std::isnan(best_sp) ? std::string("not measured") : num(best_sp) + "x") << " | "
          << (std::isnan(best_sp) ? std::string() : num(100.0 * best_sp / ceiling, "%.0f") + " %") << " |\n";
    }
  }

  if (threads.front() == 1) {
    out << "\n## One-thread overhead over sequential\n\n(method at 1 thread / sequential - 1; what cutting and scheduling "
           "cost when there is nothing to gain.)\n\n| scene |";
    const std::vector<std::string> names = method_names(r["scenes"][0]);
    for (const std::string& m : names) {
      if (m != "sequential") out << " " << m << " |";
    }
    out << "\n|---|";
    for (std::size_t i = 1; i < names.size(); ++i) out << "---|";
    out << "\n";
    for (const Json& s : r["scenes"]) {
      out << "| " << s["name"].get<std::string>() << " |";
      const double seq = s["sequential_step_ms"].get<double>();
      for (const std::string& m : names) {
        if (m != "sequential") out << " " << num(100.0 * (step_ms(s, m, 1) / seq - 1.0), "%+.1f") << " % |";
      }
      out << "\n";
    }
  }

  out << "\n## Simulated speed-up (load-balance simulation, not measured)\n\n| scene | method |";
  for (const int p : simulate) out << " P=" << p << " |";
  out << "\n|---|---|";
  for (std::size_t i = 0; i < simulate.size(); ++i) out << "---|";
  out << "\n";
  for (const Json& s : r["scenes"]) {
    for (const std::string& m : method_names(s)) {
      if (!s["methods"][m].contains("simulated_speedup")) continue;
      out << "| " << s["name"].get<std::string>() << " | " << m << " |";
      const Json& sim = s["methods"][m]["simulated_speedup"];
      for (const int p : simulate) {
        out << " " << (sim.contains(std::to_string(p)) ? num(sim[std::to_string(p)].get<double>()) + "x" : std::string()) << " |";
      }
      out << "\n";
    }
  }

  out << "\n## Predicted from measured time per piece (simulation, not measured)\n\n(The cut for P threads run on one thread, "
         "each piece of work timed, replayed on P virtual cores: predicted_step_ms. Speed-up over a sequential run of the same "
         "steps; where P threads were measured too, the measured speed-up and measured / predicted.)\n\n| scene | method |";
  for (const int p : simulate) out << " P=" << p << " |";
  out << "\n|---|---|";
  for (std::size_t i = 0; i < simulate.size(); ++i) out << "---|";
  out << "\n";
  for (const Json& s : r["scenes"]) {
    const double seq = s["sequential_step_ms"].get<double>();
    for (const std::string& m : method_names(s)) {
      if (!s["methods"][m].contains("predicted")) continue;
      out << "| " << s["name"].get<std::string>() << " | " << m << " |";
      const Json& predicted = s["methods"][m]["predicted"];
      for (const int p : simulate) {
        const std::string key = std::to_string(p);
        if (!predicted.contains(key)) {
          out << " |";
          continue;
        }
        const double want = predicted[key]["speedup"].get<double>();
        out << " " << num(want) << "x";
        const double got = seq / step_ms(s, m, p);
        if (!std::isnan(got)) out << "; measured " << num(got) << "x (" << num(got / want) << ")";
        out << " |";
      }
      out << "\n";
    }
  }

  out << "\n## Estimated vs effective node tests per run-time task\n\n(Pearson r between the weight the calibration gave "
         "each run-time task and the node tests it took; tasks cut for P = 8 threads when simulated.)\n\n| scene | method | r | "
         "tasks |\n|---|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    for (const std::string& m : method_names(s)) {
      if (!s["methods"][m].contains("correlation")) continue;
      const Json& c = s["methods"][m]["correlation"];
      if (m != "apriori" && m != "hybrid" && m != "hybrid+history" && m != "aposteriori") continue;
      out << "| " << s["name"].get<std::string>() << " | " << m << " | " << num(c["pearson"].get<double>(), "%.3f") << " | "
          << c["tasks"] << " |\n";
    }
  }

  out << "\n## Where the time goes: hybrid per phase (ms / step)\n\n| scene | threads | calibration | depth-first | finalization "
         "|\n|---|---|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    for (const int t : threads) {
      const double c = phase_ms(s, "hybrid", t, "calibrate_ms");
      if (std::isnan(c)) continue;
      out << "| " << s["name"].get<std::string>() << " | " << t << " | " << num(c) << " | "
          << num(phase_ms(s, "hybrid", t, "traverse_ms")) << " | " << num(phase_ms(s, "hybrid", t, "finalize_ms")) << " |\n";
    }
  }

  // The run's key figures, per scene, in one table (each also in the sections above).
  out << "\n## Measured figures\n\n| figure | scene | measured |\n|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    const std::string name = s["name"].get<std::string>();
    const double seq = s["sequential_step_ms"].get<double>();
    const int two = std::find(threads.begin(), threads.end(), 2) != threads.end() ? 2 : -1;
    // How far the runs of a configuration spread, per step: a difference smaller than that is noise.
    const auto spread = [&](const char* m, int t) -> std::string {
      if (!s["methods"].contains(m) || !s["methods"][m]["threads"].contains(std::to_string(t))) return "not measured";
      const Json& run = s["methods"][m]["threads"][std::to_string(t)];
      const auto runs = run["runs_ms"].get<std::vector<double>>();
      const auto [lo, hi] = std::minmax_element(runs.begin(), runs.end());
      const int steps = s["steps"].get<int>();
      return num(*lo / steps) + "-" + num(*hi / steps) + " ms";
    };
    if (two > 0 && s["methods"].contains("hybrid") && s["methods"]["hybrid"]["threads"].contains("2")) {
      const double sp = seq / step_ms(s, "hybrid", 2);
      out << "| hybrid on 2 threads, speed-up over sequential | " << name << " | " << num(sp, "%.3f") << "x";
      const double c1 = phase_ms(s, "hybrid", 1, "traverse_ms"), c2 = phase_ms(s, "hybrid", 2, "traverse_ms");
      const double f1 = phase_ms(s, "hybrid", 1, "finalize_ms"), f2 = phase_ms(s, "hybrid", 2, "finalize_ms");
      if (!std::isnan(c1) && c2 > 0 && f2 > 0) {
        out << ": depth-first part " << num(c1 / c2) << "x, finalization " << num(f1 / f2) << "x, calibration "
            << num(phase_ms(s, "hybrid", 2, "calibrate_ms")) << " ms/step, broad phase "
            << num(phase_ms(s, "hybrid", 2, "broad_ms")) << " ms/step (serial)";
        const Json& phases = s["methods"]["hybrid"]["threads"]["2"]["phases_per_step"];
        if (phases.contains("balance_speedup")) {
          // What the cut allows: the run's tasks list-scheduled by node tests on 2 virtual cores.
          // The rest of the depth-first loss is time per node test (memory, frequency, the VM).
          const double b = phases["balance_speedup"].get<double>();
          out << "; the run's tasks list-schedule to " << num(b) << "x on 2 cores by node tests (what the task cut allows), "
              << "the depth-first part reaches " << num(100.0 * (c1 / c2) / b, "%.0f") << " % of that";
        }
      }
      out << "; runs spread over sequential " << spread("sequential", 1) << ", hybrid x2 " << spread("hybrid", 2)
          << " per step |\n";
    }
    if (threads.front() == 1) {
      for (const char* m : {"apriori", "hybrid"}) {
        const double over = 100.0 * (step_ms(s, m, 1) / seq - 1.0);
        if (std::isnan(over)) continue;
        // At one thread the method tests the same node pairs as sequential (conservation, tested);
        // what it adds is its calibration, and the rest is how the runs spread.
        out << "| " << m << " 1-thread overhead over sequential | " << name << " | " << num(over, "%+.1f") << " %: calibration "
            << num(phase_ms(s, m, 1, "calibrate_ms")) << " ms/step; runs spread over sequential " << spread("sequential", 1)
            << ", " << m << " x1 " << spread(m, 1) << " per step |\n";
      }
    }
    const double bound = s["table1"]["exploitation_bound"].get<double>();
    const double expl = seq / step_ms(s, "exploitation", max_t);
    if (!std::isnan(expl)) {
      out << "| exploitation at " << max_t << " threads (its bound: " << num(bound) << "x) | " << name << " | " << num(expl)
          << "x, " << num(100.0 * expl / std::min<double>(bound, max_t), "%.0f") << " % of min(bound, threads) |\n";
    }
    // Hybrid against work stealing, where 8 or 16 threads were measured.
    for (const int t : {8, 16}) {
      if (std::find(threads.begin(), threads.end(), t) == threads.end()) continue;
      const double stealing = seq / step_ms(s, "stealing", t);
      for (const char* m : {"hybrid", "hybrid+history"}) {
        const double sp = seq / step_ms(s, m, t);
        if (std::isnan(sp) || std::isnan(stealing)) continue;
        out << "| " << m << " against stealing at " << t << " threads | " << name << " | " << num(sp) << "x vs " << num(stealing)
            << "x (" << num(sp / stealing, "%.3f") << ") |\n";
      }
    }
    if (max_t >= 16 && s.contains("ceiling") && s["ceiling"].contains(std::to_string(max_t))) {
      double best = std::nan("");
      std::string best_method;
      for (const std::string& m : method_names(s)) {
        const double sp = seq / step_ms(s, m, max_t);
        if (m != "sequential" && !std::isnan(sp) && (std::isnan(best) || sp > best)) {
          best = sp;
          best_method = m;
        }
      }
      const double ceiling = s["ceiling"][std::to_string(max_t)]["ceiling_speedup"].get<double>();
      const std::string measured = std::isnan(best)
                                       ? std::string("not measured")
                                       : best_method + " " + num(best) + "x, " + num(100.0 * best / ceiling, "%.0f") + " % of it";
      out << "| best method at " << max_t << " threads (the machine's ceiling: " << num(ceiling) << "x) | " << name << " | "
          << measured << " |\n";
    }
    if (s["methods"].contains("hybrid") && s["methods"]["hybrid"].contains("simulated_speedup") &&
        s["methods"]["hybrid"]["simulated_speedup"].contains("8")) {
      const double p8 = s["methods"]["hybrid"]["simulated_speedup"]["8"].get<double>();
      out << "| hybrid at P = 8, simulated (not measured) | " << name << " | " << num(p8) << "x |\n";
    }
    if (s["methods"].contains("hybrid") && s["methods"]["hybrid"].contains("correlation") && s["methods"].contains("apriori") &&
        s["methods"]["apriori"].contains("correlation")) {
      const double h = s["methods"]["hybrid"]["correlation"]["pearson"].get<double>();
      const double a = s["methods"]["apriori"]["correlation"]["pearson"].get<double>();
      out << "| estimate against effective node tests, Pearson r: hybrid vs apriori | " << name << " | r = " << num(h, "%.3f")
          << " vs " << num(a, "%.3f");
      if (s["methods"].contains("hybrid+history") && s["methods"]["hybrid+history"].contains("correlation")) {
        // The variant that weighs nodes by last step's node tests (not in the paper), for comparison.
        out << " (hybrid+history: r = " << num(s["methods"]["hybrid+history"]["correlation"]["pearson"].get<double>(), "%.3f")
            << ")";
      }
      out << " |\n";
    }
  }
  out << "| sequential interference against FCL | all | see the peer comparison below |\n";

  out << "\n## Peer comparison: FCL\n\n";
  std::string fcl = r["fcl_report"].get<std::string>();
  if (fcl.rfind("# ", 0) == 0) fcl = fcl.substr(fcl.find('\n') + 1);
  out << fcl << "\n";

  out << "\n## Figures\n\n";
  const std::string note = r.contains("figures_note") ? r["figures_note"].get<std::string>() : "";
  if (!note.empty()) out << note << "\n\n";
  const auto dir = file.parent_path();
  for (const Json& s : r["scenes"]) {
    const std::string png = "speedup_" + s["name"].get<std::string>() + ".png";
    if (std::filesystem::exists(dir / png)) out << "![speed-up, " << s["name"].get<std::string>() << "](" << png << ")\n";
  }
  for (const char* png : {"correlation.png", "gantt.png"}) {
    if (std::filesystem::exists(dir / png)) out << "\n![" << png << "](" << png << ")\n";
  }
  out << "\nSpeed-up figures: measured thread counts solid, simulated core counts dashed, the linear limit dotted. "
         "Correlation: estimated vs effective node tests per run-time task (log-log). Gantt: one step of "
      << (r.contains("gantt") ? r["gantt"]["scene"].get<std::string>() : std::string("a scene")) << ", exploitation vs hybrid, "
      << "one row per thread (stage, depth-first, finalization).\n";
  output.commit();
}

}  // namespace caliber::cli
