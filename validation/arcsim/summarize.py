#!/usr/bin/env python3
"""Tables and plots of the original's 42 cloth scenes, from the runs of run_all.sh.

Reads <out>/<set>/<scene>/{log.jsonl, frame_NNNN.obj, exit_code, wall_seconds, stderr.txt} and writes
- <results>: one row per scene (simulated time, steps, wall time per simulated second, Newton iterations per step,
  substeps, steps not converged, exit code, final elastic energy, final bounding box) and the stretch scenes' handle
  forces at 0.1, 0.2, 0.3, 0.4 s (with the original's published 2D stock_stretchX values);
- (`hylc simulate` itself writes <out>/<set>/<scene>/handle_forces.csv for every scene that holds vertices: time,
  and fx, fy, fz, |F| per held set);
- <plots>/arcsim_<set>_<stretchX|stretchY>.png: handle |F| over time for the five materials (1D and 2D; needs
  matplotlib, installed with `pip install --user matplotlib` when missing).

Usage: summarize.py --out out/arcsim --results validation/arcsim/results.md --plots validation/arcsim
"""

import argparse
import glob
import json
import math
import os
import subprocess
import sys

SETS = ["1D", "2D", "small"]
MATERIALS = ["basket", "honey", "rib", "satin", "stock"]
TIMES = [0.1, 0.2, 0.3, 0.4]
# the original simulator on tests/2D/conf/stock_stretchX.json (remeshing on), |Fx| in N
REFERENCE = {"2D/stock_stretchX": [0.83, 1.70, 2.97, 4.23]}


def read_log(path):
    steps = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line:
                steps.append(json.loads(line))
    return steps


def last_frame(run_dir):
    frames = sorted(glob.glob(os.path.join(run_dir, "frame_*.obj")))
    return frames[-1] if frames else None


def bounding_box(obj):
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    with open(obj) as f:
        for line in f:
            if line.startswith("v "):
                p = [float(c) for c in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, p)]
                hi = [max(a, b) for a, b in zip(hi, p)]
    return lo, hi


def read_text(path, default=""):
    try:
        with open(path) as f:
            return f.read().strip()
    except OSError:
        return default


def error_line(run_dir):
    lines = [l for l in read_text(os.path.join(run_dir, "stderr.txt")).splitlines() if "warning:" not in l
             and "note:" not in l]
    return lines[-1] if lines else ""


def norm(v):
    return math.sqrt(sum(c * c for c in v))


def forces_over_time(steps):
    """[(time, {name: [fx, fy, fz]})] of the steps."""
    return [(s["time"], {n: f for n, f in s.get("handle_forces", [])}) for s in steps]


def force_at(series, t):
    """The handles' forces at the step whose time is closest to t (None when the run did not get there)."""
    if not series or series[-1][0] < t - 0.5 * series[0][0]:
        return None
    return min(series, key=lambda s: abs(s[0] - t))[1]


def summarize_run(set_name, scene, run_dir):
    row = {"id": f"{set_name}/{scene}", "set": set_name, "scene": scene}
    row["exit"] = read_text(os.path.join(run_dir, "exit_code"), "?")
    row["wall_total"] = float(read_text(os.path.join(run_dir, "wall_seconds"), "nan") or "nan")
    row["error"] = error_line(run_dir) if row["exit"] not in ("0", "?") else ""
    log = os.path.join(run_dir, "log.jsonl")
    steps = read_log(log) if os.path.exists(log) else []
    row["steps"] = len(steps)
    if steps:
        sim = steps[-1]["time"]
        wall = sum(s["wall"] for s in steps)
        newton = [s["newton"] for s in steps]
        subs = [s.get("substeps", 1) for s in steps]
        row.update(
            simulated=sim,
            wall_per_s=wall / sim if sim > 0 else math.nan,
            newton_mean=sum(newton) / len(newton),
            newton_max=max(newton),
            substeps_total=sum(subs),
            substeps_max=max(subs),
            dt_min=min(s.get("dt_min", math.nan) for s in steps),
            unconverged=sum(1 for s in steps if not s["converged"]),
            energy=steps[-1]["energy_elastic"],
        )
    series = forces_over_time(steps)
    row["series"] = series
    obj = last_frame(run_dir)
    row["bbox"] = bounding_box(obj) if obj else None
    return row


def fmt(x, spec):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    return format(x, spec)


def table(rows):
    out = [
        "| scene | simulated (s) | steps | wall / simulated s (s) | Newton / step (mean, max) | substeps "
        "(total, max per step) | smallest substep (s) | steps not converged | exit | final elastic energy (J) | "
        "final bounding box (m) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    for r in rows:
        bb = r["bbox"]
        bbs = ("[" + ", ".join(f"{c:.4f}" for c in bb[0]) + "] – [" + ", ".join(f"{c:.4f}" for c in bb[1]) + "]"
               if bb else "–")
        if "simulated" in r:
            out.append(
                f"| {r['id']} | {r['simulated']:.3f} | {r['steps']} | {fmt(r['wall_per_s'], '.2f')} | "
                f"{r['newton_mean']:.1f}, {r['newton_max']} | {r['substeps_total']}, {r['substeps_max']} | "
                f"{fmt(r['dt_min'], '.2e')} | {r['unconverged']} | {r['exit']} | {r['energy']:.4e} | {bbs} |"
            )
        else:
            out.append(f"| {r['id']} | – | 0 | – | – | – | – | – | {r['exit']} | – | {bbs} |")
    return out


def forces_table(rows):
    stretch = [r for r in rows if "stretch" in r["scene"] and r["series"]]
    if not stretch:
        return []
    out = [
        "",
        "Handle forces of the stretch scenes: |F| (N) of each handle at the step nearest to t (the whole series is in "
        "`<out>/<set>/<scene>/handle_forces.csv`).",
        "",
        "| scene | handle | " + " | ".join(f"t = {t} s" for t in TIMES) + " |",
        "| --- | --- | " + " | ".join("---:" for _ in TIMES) + " |",
    ]
    for r in stretch:
        names = list(r["series"][0][1].keys())
        for n in names:
            vals = []
            for t in TIMES:
                f = force_at(r["series"], t)
                vals.append(f"{norm(f[n]):.3f}" if f and n in f else "–")
            out.append(f"| {r['id']} | {n} | " + " | ".join(vals) + " |")
        if r["id"] in REFERENCE:
            out.append(f"| {r['id']} | the original (remeshing on), \\|Fx\\| | "
                       + " | ".join(f"{v:.2f}" for v in REFERENCE[r["id"]]) + " |")
            for n in names:
                vals = []
                for t, ref in zip(TIMES, REFERENCE[r["id"]]):
                    f = force_at(r["series"], t)
                    vals.append(f"{abs(f[n][0]):.3f} ({100 * (abs(f[n][0]) / ref - 1):+.0f} %)" if f and n in f
                                else "–")
                out.append(f"| {r['id']} | {n}: \\|Fx\\| (vs the original) | " + " | ".join(vals) + " |")
    return out


def ensure_matplotlib():
    try:
        import matplotlib  # noqa: F401
        return True
    except ImportError:
        print("matplotlib missing: pip install --user matplotlib", file=sys.stderr)
        r = subprocess.run([sys.executable, "-m", "pip", "install", "--user", "--quiet", "matplotlib"])
        if r.returncode != 0:
            return False
        import site
        import importlib
        sys.path.append(site.getusersitepackages())
        importlib.invalidate_caches()
        try:
            import matplotlib  # noqa: F401
            return True
        except ImportError:
            return False


def plots(rows, plot_dir):
    by_id = {r["id"]: r for r in rows}
    families = [(s, fam) for s in ["1D", "2D"] for fam in ["stretchX", "stretchY"]]
    wanted = [(s, fam) for s, fam in families
              if any(f"{s}/{m}_{fam}" in by_id and by_id[f"{s}/{m}_{fam}"]["series"] for m in MATERIALS)]
    if not wanted:
        return []
    if not ensure_matplotlib():
        print("plots skipped: matplotlib could not be installed", file=sys.stderr)
        return []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    written = []
    for s, fam in wanted:
        fig, ax = plt.subplots(figsize=(7, 4.2))
        for k, m in enumerate(MATERIALS):
            r = by_id.get(f"{s}/{m}_{fam}")
            if not r or not r["series"]:
                continue
            names = list(r["series"][0][1].keys())
            t = [p[0] for p in r["series"]]
            for j, n in enumerate(names):
                ax.plot(t, [norm(p[1][n]) for p in r["series"]], color=f"C{k}",
                        linestyle="-" if j == 0 else "--", label=f"{m} ({n})")
        if f"{s}/stock_{fam}" in REFERENCE:
            ax.plot(TIMES, REFERENCE[f"{s}/stock_{fam}"], "k^", label="stock, the original (|Fx|)")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("handle force |F| (N)")
        ax.set_title(f"ARCSim-HYLC scenes, {s} {fam}: handle force over time")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        path = os.path.join(plot_dir, f"arcsim_{s}_{fam}.png")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/arcsim")
    ap.add_argument("--results", default="validation/arcsim/results.md")
    ap.add_argument("--plots", default="validation/arcsim")
    a = ap.parse_args()
    rows = []
    for s in SETS:
        for run_dir in sorted(glob.glob(os.path.join(a.out, s, "*"))):
            if os.path.isdir(run_dir):
                rows.append(summarize_run(s, os.path.basename(run_dir), run_dir))
    if not rows:
        print(f"no runs in {a.out}", file=sys.stderr)
        return 1
    pngs = plots(rows, a.plots)
    done = [r for r in rows if "simulated" in r]
    lines = [
        "# The original's cloth scenes (ARCSim-HYLC) with `hylc simulate`",
        "",
        "Written by `validation/arcsim/run_all.sh` (`summarize.py`): each ARCSim scene read as it is (converted, "
        "fixed `hylc_square.obj` mesh, no remeshing), "
        + (f"with `{os.environ['FLAGS']}`" if os.environ.get("FLAGS") else "with the conversion's settings")
        + " (frames of 1/60 s; `--time-tol off`: one implicit step per frame, halved when Newton fails). "
        "Wall time per simulated second sums the steps' wall times (setup excluded). Machine: "
        f"{os.cpu_count()} cores.",
        "",
        f"{len(rows)} scenes, {sum(r.get('unconverged', 0) for r in done)} steps not converged in all, "
        f"{sum(1 for r in rows if r['exit'] != '0')} runs with a non-zero exit code.",
        "",
    ]
    lines += table(rows)
    failed = [r for r in rows if r["error"]]
    if failed:
        lines += ["", "Runs that stopped:", ""]
        lines += [f"- {r['id']} (exit {r['exit']}): {r['error']}" for r in failed]
    lines += forces_table(rows)
    if pngs:
        lines += ["", "Plots (handle |F| over time, solid: first handle, dashed: second):", ""]
        lines += [f"![{os.path.basename(p)}]({os.path.basename(p)})" for p in pngs]
    with open(a.results, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {a.results}" + "".join(f", {p}" for p in pngs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
