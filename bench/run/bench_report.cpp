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
#include "report_tables.h"
#include "timing.h"
#include "caliber/error.h"

namespace caliber::cli {
namespace {

using report::Json;
using report::method_names;
using report::num;
using report::phase_ms;
using report::step_ms;
using report::write_key_figures;

/// The intro: the machine, how the runs were made, how far the bench got; false when no scene has a reference yet.
bool write_intro(std::ostream& out, const Json& r) {
  const std::vector<int> simulate = r["simulate"].get<std::vector<int>>();
  const int cores = r["hardware_threads"].get<int>();
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
    return false;
  }
  out << "Real (measured) figures stop at this machine's " << cores << " hardware thread(s); the columns P = ";
  for (std::size_t i = 0; i < simulate.size(); ++i) out << (i ? ", " : "") << simulate[i];
  out << " are the **load-balance simulation** (node tests of the run-time tasks, cut for P threads, list-scheduled on P "
         "virtual cores; "
      << (r["simulate_steps"].get<int>() > 0 ? "first " + std::to_string(r["simulate_steps"].get<int>()) + " steps"
                                             : std::string("every step"))
      << "), not measurements.\n\n";
  return true;
}

/// Table 1: the scenes.
void write_table1(std::ostream& out, const Json& r) {
  out << "## Table 1: scenes\n\n| scene | objects | triangles | node tests / step | contacts / step | pairs / step | "
         "distinct pairs | heaviest pair | second | exploitation bound | sequential ms / step "
         "|\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    const Json& t = s["table1"];
    out << "| " << s["name"].get<std::string>() << " | " << t["objects"] << " | " << t["triangles"] << " | "
        << num(t["node_tests_per_step"].get<double>(), "%.0f") << " | " << num(t["contacts_per_step"].get<double>(), "%.1f")
        << " | " << num(t["pairs_per_step"].get<double>(), "%.1f") << " | " << t["distinct_pairs"] << " | "
        << num(100 * t["heaviest_pair_share"].get<double>(), "%.1f") << " % | "
        << num(100 * t["second_pair_share"].get<double>(), "%.1f") << " % | " << num(t["exploitation_bound"].get<double>())
        << "x | " << num(s["sequential_step_ms"].get<double>()) << " |\n";
  }
}

/// Table 2: time per step and speed-up over sequential.
void write_table2(std::ostream& out, const Json& r) {
  const std::vector<int> threads = r["threads"].get<std::vector<int>>();
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
}

/// The machine's ceiling, and each method's share of it.
void write_ceiling(std::ostream& out, const Json& r) {
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
}

/// The one-thread overhead of every method over sequential.
void write_overhead(std::ostream& out, const Json& r) {
  const std::vector<int> threads = r["threads"].get<std::vector<int>>();
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
}

/// The load-balance simulation by node tests.
void write_simulated(std::ostream& out, const Json& r) {
  const std::vector<int> simulate = r["simulate"].get<std::vector<int>>();
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
}

/// The prediction from measured time per piece.
void write_predicted(std::ostream& out, const Json& r) {
  const std::vector<int> simulate = r["simulate"].get<std::vector<int>>();
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
}

/// The estimate's correlation with the node tests.
void write_correlation(std::ostream& out, const Json& r) {
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
}

/// Hybrid's time per phase.
void write_phases(std::ostream& out, const Json& r) {
  const std::vector<int> threads = r["threads"].get<std::vector<int>>();
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
}

/// The FCL comparison and the figures.
void write_peers_and_figures(std::ostream& out, const Json& r, const std::filesystem::path& file) {
  out << "\n## Peer comparison: FCL\n\n";
  std::string fcl = r["fcl_report"].get<std::string>();
  if (fcl.rfind("# ", 0) == 0) fcl = fcl.substr(fcl.find('\n') + 1);
  out << fcl << "\n";

  out << "\n## Figures\n\n";
  const std::string note = r.contains("figures_note") ? r["figures_note"].get<std::string>() : "";
  if (!note.empty()) out << note << "\n\n";
  const auto dir = file.parent_path();
  for (const Json& s : r["scenes"]) {
    const std::string svg = "speedup_" + s["name"].get<std::string>() + ".svg";
    if (std::filesystem::exists(dir / svg)) out << "![speed-up, " << s["name"].get<std::string>() << "](" << svg << ")\n";
  }
  for (const char* svg : {"correlation.svg", "gantt.svg"}) {
    if (std::filesystem::exists(dir / svg)) out << "\n![" << svg << "](" << svg << ")\n";
  }
  out << "\nSpeed-up figures: measured thread counts solid, simulated core counts dashed, the linear limit dotted. "
         "Correlation: estimated vs effective node tests per run-time task (log-log). Gantt: one step of "
      << (r.contains("gantt") ? r["gantt"]["scene"].get<std::string>() : std::string("a scene")) << ", exploitation vs hybrid, "
      << "one row per thread (stage, depth-first, finalization).\n";
}

}  // namespace

void write_bench_report(const Json& r, const std::filesystem::path& file) {
  cli::OutputFile output(file.string(), "report.md");  // written whole, or not at all
  std::ostream& out = output.stream();
  if (write_intro(out, r)) {
    write_table1(out, r);
    write_table2(out, r);
    write_ceiling(out, r);
    write_overhead(out, r);
    write_simulated(out, r);
    write_predicted(out, r);
    write_correlation(out, r);
    write_phases(out, r);
    write_key_figures(out, r);
    write_peers_and_figures(out, r, file);
  }
  output.commit();
}

}  // namespace caliber::cli
