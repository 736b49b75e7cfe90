// The table of key figures of caliber-bench's report.md (report_tables.h): per scene, hybrid on 2
// threads and its phases, the one-thread overhead, exploitation against its bound, hybrid against
// stealing, the best method against the machine's ceiling, the simulation and the estimate.

#include "report_tables.h"

#include "timing.h"

namespace caliber::cli::report {
namespace {

/// How far the runs of a configuration spread, per step: a difference smaller than that is noise.
std::string spread(const Json& s, const char* m, int t) {
  if (!s["methods"].contains(m) || !s["methods"][m]["threads"].contains(std::to_string(t))) return "not measured";
  const Json& run = s["methods"][m]["threads"][std::to_string(t)];
  const auto runs = run["runs_ms"].get<std::vector<double>>();
  const auto [lo, hi] = std::minmax_element(runs.begin(), runs.end());
  const int steps = s["steps"].get<int>();
  return num(*lo / steps) + "-" + num(*hi / steps) + " ms";
}

/// Key figures: hybrid on 2 threads, its phases and how far its runs spread.
void key_hybrid_two(std::ostream& out, const Json& s, const std::string& name, double seq, const std::vector<int>& threads) {
  const int two = std::find(threads.begin(), threads.end(), 2) != threads.end() ? 2 : -1;
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
    out << "; runs spread over sequential " << spread(s, "sequential", 1) << ", hybrid x2 " << spread(s, "hybrid", 2)
        << " per step |\n";
  }
}

/// Key figures: the calibrated methods' one-thread overhead over sequential.
void key_overhead(std::ostream& out, const Json& s, const std::string& name, double seq, const std::vector<int>& threads) {
  if (threads.front() == 1) {
    for (const char* m : {"apriori", "hybrid"}) {
      const double over = 100.0 * (step_ms(s, m, 1) / seq - 1.0);
      if (std::isnan(over)) continue;
      // At one thread the method tests the same node pairs as sequential (conservation, tested);
      // what it adds is its calibration, and the rest is how the runs spread.
      out << "| " << m << " 1-thread overhead over sequential | " << name << " | " << num(over, "%+.1f") << " %: calibration "
          << num(phase_ms(s, m, 1, "calibrate_ms")) << " ms/step; runs spread over sequential " << spread(s, "sequential", 1)
          << ", " << m << " x1 " << spread(s, m, 1) << " per step |\n";
    }
  }
}

/// Key figures: exploitation against its bound, and hybrid against stealing at 8 and 16 threads.
void key_exploitation(std::ostream& out, const Json& s, const std::string& name, double seq, const std::vector<int>& threads) {
  const int max_t = threads.back();
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
}

/// Key figures: the best method against the machine's ceiling, the simulation at P = 8 and the estimate's correlation.
void key_ceiling_and_estimates(std::ostream& out, const Json& s, const std::string& name, double seq,
                               const std::vector<int>& threads) {
  const int max_t = threads.back();
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

}  // namespace

/// The run's key figures, per scene, in one table (each also in the sections above).
void write_key_figures(std::ostream& out, const Json& r) {
  const std::vector<int> threads = r["threads"].get<std::vector<int>>();
  // The run's key figures, per scene, in one table (each also in the sections above).
  out << "\n## Measured figures\n\n| figure | scene | measured |\n|---|---|---|\n";
  for (const Json& s : r["scenes"]) {
    const std::string name = s["name"].get<std::string>();
    const double seq = s["sequential_step_ms"].get<double>();
    key_hybrid_two(out, s, name, seq, threads);
    key_overhead(out, s, name, seq, threads);
    key_exploitation(out, s, name, seq, threads);
    key_ceiling_and_estimates(out, s, name, seq, threads);
  }
  out << "| sequential interference against FCL | all | see the peer comparison below |\n";
}

}  // namespace caliber::cli::report
