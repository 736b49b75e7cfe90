#!/usr/bin/env python3
"""Figures of a `caliber-bench` run, from DIR/results.json (python3-matplotlib, Debian's package).

    python3 scripts/plot_bench.py DIR

Writes into DIR, as PNG and SVG:
  speedup_<scene>   speed-up vs threads per method: measured thread counts solid, the load-balance
                    simulation dashed, the linear limit dotted (the paper's Fig. 10);
  correlation       estimated vs effective node tests per run-time task, with Pearson r, for the
                    calibrated methods (the paper's Fig. 11);
  gantt             one step per thread, exploitation vs hybrid (stage, depth-first, finalization).
`caliber-bench` runs this itself; it still writes report.md when this cannot run.
"""

import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLORS = {
    "sequential": "#444444",
    "exploitation": "#1f77b4",
    "stealing": "#ff7f0e",
    "aposteriori": "#2ca02c",
    "apriori": "#9467bd",
    "hybrid": "#d62728",
    "hybrid+history": "#8c564b",
}
PHASE_COLORS = {"stage": "#9467bd", "traverse": "#1f77b4", "finalize": "#ff7f0e"}


def save(fig, out, name):
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out, f"{name}.{ext}"), dpi=110, bbox_inches="tight")
    plt.close(fig)


def speedup_figures(r, out):
    threads = r["threads"]
    simulate = r["simulate"]
    cores = r["hardware_threads"]
    for s in r["scenes"]:
        seq = s["sequential_step_ms"]
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        top = max(threads + simulate)
        ax.plot([1, top], [1, top], ":", color="#999999", label="linear")
        for name, m in s["methods"].items():
            if name == "sequential":
                continue
            color = COLORS.get(name, None)
            xs = [t for t in threads if str(t) in m["threads"]]
            ys = [seq / m["threads"][str(t)]["step_ms"] for t in xs]
            ax.plot(xs, ys, "-o", color=color, label=f"{name} (measured)", markersize=4)
            sim = m.get("simulated_speedup", {})
            sx = [p for p in simulate if str(p) in sim]
            if sx:
                # Join the simulation to the last measured point so the two read as one curve.
                jx = ([xs[-1]] if xs else []) + sx
                jy = ([ys[-1]] if ys else []) + [sim[str(p)] for p in sx]
                ax.plot(jx, jy, "--", color=color, alpha=0.8, marker="x", markersize=4)
        ax.set_xscale("log", base=2)
        ax.set_yscale("log", base=2)
        ax.set_xlabel("threads (measured up to %d, then simulated cores)" % cores)
        ax.set_ylabel("speed-up over sequential")
        ax.set_title(f"{s['name']}: sequential {seq:.1f} ms/step")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
        save(fig, out, f"speedup_{s['name']}")


def correlation_figure(r, out):
    panels = []
    for s in r["scenes"]:
        for name in ("apriori", "hybrid", "hybrid+history"):
            m = s["methods"].get(name)
            if m and "correlation" in m and m["correlation"]["points"]:
                panels.append((s["name"], name, m["correlation"]))
    if not panels:
        return
    cols = min(4, len(panels))
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.2 * rows), squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.axis("off")
    for ax, (scene, name, c) in zip(axes.flat, panels):
        xs = [max(p[0], 1e-3) for p in c["points"]]
        ys = [max(p[1], 0.5) for p in c["points"]]
        ax.scatter(xs, ys, s=4, alpha=0.4, color=COLORS.get(name), rasterized=True)  # thousands of points: a bitmap inside the SVG
        lo, hi = min(xs + ys), max(xs + ys)
        ax.plot([lo, hi], [lo, hi], ":", color="#999999")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{scene}, {name}: r = {c['pearson']:.2f}", fontsize=9)
        ax.set_xlabel("estimated weight", fontsize=8)
        ax.set_ylabel("effective node tests", fontsize=8)
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    save(fig, out, "correlation")


def gantt_figure(r, out):
    g = r.get("gantt")
    if not g:
        return
    methods = list(g["methods"].items())
    fig, axes = plt.subplots(len(methods), 1, figsize=(8, 1.2 + 0.45 * g["threads"] * len(methods)), squeeze=False)
    end = max([sp[2] for _, m in methods for sp in m["spans"]] + [1e-3])
    for ax, (name, m) in zip(axes.flat, methods):
        for thread, start, stop, phase in m["spans"]:
            ax.broken_barh([(start, max(stop - start, end * 1e-4))], (thread - 0.4, 0.8), color=PHASE_COLORS[phase],
                           edgecolor="white", linewidth=0.2)
        ax.set_yticks(range(g["threads"]))
        ax.set_yticklabels([f"thread {t}" for t in range(g["threads"])], fontsize=7)
        ax.set_xlim(0, end * 1.02)
        ax.set_title(f"{name}: {g['scene']} step {g['step']}, {g['threads']} threads, narrow phase {m['narrow_ms']:.1f} ms",
                     fontsize=9)
        ax.invert_yaxis()
    axes.flat[-1].set_xlabel("ms since the start of the narrow phase")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in PHASE_COLORS.values()]
    axes.flat[0].legend(handles, ["weight-driven stage", "depth-first", "finalization"], fontsize=7, loc="upper right")
    fig.tight_layout()
    save(fig, out, "gantt")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_bench.py DIR (with DIR/results.json from caliber-bench)")
    out = sys.argv[1]
    with open(os.path.join(out, "results.json")) as f:
        r = json.load(f)
    speedup_figures(r, out)
    correlation_figure(r, out)
    gantt_figure(r, out)


if __name__ == "__main__":
    main()
