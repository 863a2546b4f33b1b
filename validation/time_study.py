#!/usr/bin/env python3
"""Accuracy against wall time of the cloth solver's time integration, by self-convergence.

For each scene, runs `hylc simulate SCENE --duration D --out OUT/<scene>/<config>` for a set of integrator settings
(fixed substeps of implicit Euler and BDF2, `--time-tol` with both, the original's linearised scheme with its
`frame_steps`), and compares every run's per-frame handle force (the sum of |F| over the held sets) and elastic
energy with a reference run of the same scene with a much smaller step (BDF2, dt/32; --ref-substeps). Writes a markdown
table (per scene and configuration: force RMS error over the frames from 0.1 s relative to the reference's RMS
force, the largest relative energy error over the frames from 0.05 s, the force error at the last frame, substeps,
Newton iterations, CPU and wall time per simulated second) and a PNG per scene (error against CPU time).

Resumable: a run whose folder holds `done.json` is not repeated (delete the folder to rerun it). The runs are
serial (each uses both cores).

Usage:
  validation/time_study.py [--hylc target/release/hylc] [--out out/time_study]
      [--results docs/time-study.md] [--plots docs/time-study] [--scenes basket_stretchX,...] [--configs a,b]
      [--list] [--report-only]

The scenes are the original's ARCSim files under ../shared/data/arcsim-hylc/tests/2D/conf; without that folder the
script stops with a message.
"""

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONF = os.path.join(ROOT, "..", "shared", "data", "arcsim-hylc", "tests", "2D", "conf")

# scene: (simulated duration, the original's frame_steps)
SCENES = {
    "basket_stretchX": (0.5, 80),
    "rib_stretchY": (0.3, 80),
    "stock_stretchX": (0.4, 80),
    "honey_drapeX": (0.4, 100),
}

REF_SUBSTEPS = 32  # the reference: BDF2 with dt / 32 (1/1916 s for the originals' frame time); --ref-substeps

# name: (flags, label)
CONFIGS = {
    "ie-1": (["--time-tol", "off"], "implicit Euler, dt"),
    "ie-2": (["--time-tol", "off", "--substeps", "2"], "implicit Euler, dt/2"),
    "ie-4": (["--time-tol", "off", "--substeps", "4"], "implicit Euler, dt/4"),
    "ie-8": (["--time-tol", "off", "--substeps", "8"], "implicit Euler, dt/8"),
    "bdf2-1": (["--time-tol", "off", "--integrator", "bdf2"], "BDF2, dt"),
    "bdf2-2": (["--time-tol", "off", "--integrator", "bdf2", "--substeps", "2"], "BDF2, dt/2"),
    "bdf2-4": (["--time-tol", "off", "--integrator", "bdf2", "--substeps", "4"], "BDF2, dt/4"),
    "ie-tol-1e-4": (["--time-tol", "1e-4"], "implicit Euler, τ 1e-4 m (the default)"),
    "ie-tol-1e-5": (["--time-tol", "1e-5"], "implicit Euler, τ 1e-5 m"),
    "bdf2-tol-1e-4": (["--integrator", "bdf2", "--time-tol", "1e-4"], "BDF2, τ 1e-4 m"),
    "bdf2-tol-1e-5": (["--integrator", "bdf2", "--time-tol", "1e-5"], "BDF2, τ 1e-5 m"),
    "bdf2-tol-1e-6": (["--integrator", "bdf2", "--time-tol", "1e-6"], "BDF2, τ 1e-6 m"),
    "linearized": (None, "linearised (original's), frame_steps"),
}


def die(msg):
    print(f"time_study.py: {msg}", file=sys.stderr)
    sys.exit(2)


def flags_of(config, scene):
    flags, _ = CONFIGS[config]
    if flags is None:  # the original's scheme with its own substeps
        return ["--time-tol", "off", "--integrator", "linearized", "--substeps", str(SCENES[scene][1])]
    return flags


def run(hylc, scene, config, out, flags, report_only=False):
    """Run one configuration (unless done) and return its done.json record; with `report_only` None when it is
    not done."""
    d = os.path.join(out, scene, config)
    done = os.path.join(d, "done.json")
    if os.path.exists(done):
        with open(done) as f:
            return json.load(f)
    if report_only:
        return None
    duration = SCENES[scene][0]
    cmd = [hylc, "simulate", os.path.join(CONF, scene + ".json"), "--quiet", "--duration", str(duration),
           "--out", d] + flags
    print(f"{scene} {config}: {' '.join(flags) or '(defaults)'}", flush=True)
    t0 = time.time()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if p.returncode != 0:
        lines = [l for l in p.stderr.splitlines() if "warning" not in l]
        print(f"  exit {p.returncode}: {lines[-1] if lines else ''}", flush=True)
    rec = {"scene": scene, "config": config, "flags": flags, "exit": p.returncode, "wall": wall, "cpu": cpu,
           "duration": duration}
    os.makedirs(d, exist_ok=True)
    with open(done, "w") as f:
        json.dump(rec, f)
    return rec


def frames(out, scene, config):
    """[(time, force, energy, substeps, newton)] per frame of a run's log."""
    path = os.path.join(out, scene, config, "log.jsonl")
    rows = []
    try:
        with open(path) as f:
            for n, line in enumerate(f, 1):
                try:
                    r = json.loads(line)
                except json.JSONDecodeError as e:
                    die(f"{path}:{n}: not a JSON line ({e})")
                force = sum(math.sqrt(sum(c * c for c in v)) for _, v in r.get("handle_forces", []))
                rows.append((r["time"], force, r["energy_elastic"], r["substeps"], r["newton"]))
    except FileNotFoundError:
        return []
    return rows


def compare(run_rows, ref_rows):
    """Force RMS error (relative to the reference's RMS force) from 0.1 s, the largest relative energy error from
    0.05 s and the relative force error at the last frame; None when the run is incomplete."""
    if not run_rows or len(run_rows) != len(ref_rows):
        return None
    df, rf, de = [], [], []
    for (t, f, e, _, _), (tr, fr, er, _, _) in zip(run_rows, ref_rows):
        if abs(t - tr) > 1e-9:
            die(f"frame times differ: {t} against the reference's {tr}")
        if t >= 0.1 - 1e-9:
            df.append((f - fr) ** 2)
            rf.append(fr ** 2)
        if t >= 0.05 - 1e-9 and er != 0:
            de.append(abs(e - er) / abs(er))
    force_rms = math.sqrt(sum(df) / sum(rf)) if rf and sum(rf) > 0 else float("nan")
    last = run_rows[-1][1], ref_rows[-1][1]
    last_err = abs(last[0] - last[1]) / abs(last[1]) if last[1] else float("nan")
    return force_rms, max(de) if de else float("nan"), last_err


def plot(out_png, scene, points, ref_substeps):
    try:
        import matplotlib
    except ImportError:
        subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "matplotlib"], check=False)
        import importlib
        importlib.invalidate_caches()
        import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, k, what in [(axes[0], 1, "handle force RMS error (relative, frames from 0.1 s)"),
                        (axes[1], 2, "largest energy error (relative, frames from 0.05 s)")]:
        for family, marker in [("implicit Euler", "o"), ("BDF2", "s"), ("linearised", "^")]:
            pts = [p for p in points if p[3].startswith(family)]
            if pts:
                ax.loglog([p[0] for p in pts], [p[k] for p in pts], marker, label=family)
                for p in pts:
                    ax.annotate(p[3].split(", ", 1)[-1], (p[0], p[k]), fontsize=7, xytext=(3, 3),
                                textcoords="offset points")
        ax.xaxis.set_major_locator(matplotlib.ticker.FixedLocator(
            [10, 20, 30, 50, 70, 100, 200, 300, 500, 700, 1000, 2000, 3000, 5000]))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.set_xlabel("CPU time per simulated second (s)")
        ax.set_ylabel(what)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle(f"2D/{scene}: error against cost (reference: BDF2, dt/{ref_substeps})")
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hylc", default=os.path.join(ROOT, "target", "release", "hylc"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "time_study"))
    ap.add_argument("--results", default=os.path.join(ROOT, "docs", "time-study.md"))
    ap.add_argument("--plots", default=os.path.join(ROOT, "docs", "time-study"))
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--configs", default=",".join(CONFIGS))
    ap.add_argument("--ref-substeps", type=int, default=REF_SUBSTEPS,
                    help=f"the reference's fixed substeps per frame (BDF2; default {REF_SUBSTEPS})")
    ap.add_argument("--list", action="store_true", help="print the scenes and configurations and exit")
    ap.add_argument("--report-only", action="store_true",
                    help="run nothing: write the tables and plots of the runs that are done (the others: not run yet)")
    a = ap.parse_args()
    if a.list:
        for s, (d, k) in SCENES.items():
            print(f"scene {s}: {d} s, frame_steps {k}")
        for c, (f, lab) in CONFIGS.items():
            print(f"config {c}: {lab}")
        return
    scenes = [s for s in a.scenes.split(",") if s]
    configs = [c for c in a.configs.split(",") if c]
    for s in scenes:
        if s not in SCENES:
            die(f"--scenes: unknown scene {s!r} (one of {', '.join(SCENES)})")
    for c in configs:
        if c not in CONFIGS:
            die(f"--configs: unknown configuration {c!r} (one of {', '.join(CONFIGS)})")
    if not os.path.isdir(CONF):
        die(f"{CONF}: the original's scenes are not there (the study needs ../shared)")
    if not os.path.exists(a.hylc):
        die(f"{a.hylc}: no such binary (cargo build --release)")
    lines = [
        "# Time integration: accuracy against cost",
        "",
        f"Written by `validation/time_study.py`. Reference per scene: BDF2 with dt/{a.ref_substeps} (fixed substeps).",
        "Force: the sum of |F| over the held sets per frame; its error is the RMS over the frames from 0.1 s",
        "relative to the reference's RMS force. Energy: the largest relative error of the elastic energy over the",
        "frames from 0.05 s. Cost: CPU time (user + system, both cores) and wall time per simulated second; the",
        "CPU time is the steadier figure when other work shares the machine.",
        "",
    ]
    os.makedirs(a.plots, exist_ok=True)
    for s in scenes:
        ref_name = f"reference-{a.ref_substeps}"
        ref = run(a.hylc, s, ref_name, a.out, ["--time-tol", "off", "--integrator", "bdf2", "--substeps", str(a.ref_substeps)],
                  a.report_only)
        if ref is None:
            lines += [f"## 2D/{s} ({SCENES[s][0]} s)", "", "Not run yet.", ""]
            continue
        ref_rows = frames(a.out, s, ref_name)
        lines += [f"## 2D/{s} ({SCENES[s][0]} s)", "",
                  "| configuration | force RMS error | energy max error | last-frame force error | substeps | "
                  "Newton iterations | CPU s per simulated s | wall s per simulated s | exit |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        points = []
        ref_sub = sum(r[3] for r in ref_rows)
        ref_newton = sum(r[4] for r in ref_rows)
        lines.append(f"| reference (BDF2, dt/{a.ref_substeps}) | — | — | — | {ref_sub} | {ref_newton} | "
                     f"{ref.get('cpu', float('nan')) / ref['duration']:.1f} | "
                     f"{ref['wall'] / ref['duration']:.1f} | {ref['exit']} |")
        for c in configs:
            rec = run(a.hylc, s, c, a.out, flags_of(c, s), a.report_only)
            if rec is None:
                lines.append(f"| {CONFIGS[c][1]} | not run yet | | | | | | | |")
                continue
            rows = frames(a.out, s, c)
            cmp_ = compare(rows, ref_rows) if ref["exit"] == 0 else None
            per_s = rec["wall"] / rec["duration"]
            cpu_s = rec.get("cpu", float("nan")) / rec["duration"]
            label = CONFIGS[c][1]
            if cmp_ is None:
                lines.append(f"| {label} | — | — | — | — | — | {cpu_s:.1f} | {per_s:.1f} | {rec['exit']} |")
                continue
            f_rms, e_max, f_last = cmp_
            lines.append(f"| {label} | {f_rms:.2%} | {e_max:.2%} | {f_last:.2%} | {sum(r[3] for r in rows)} | "
                         f"{sum(r[4] for r in rows)} | {cpu_s:.1f} | {per_s:.1f} | {rec['exit']} |")
            points.append((cpu_s, f_rms, e_max, label))
        lines.append("")
        if points:
            png = os.path.join(a.plots, f"{s}.png")
            plot(png, s, points, a.ref_substeps)
            lines += [f"![{s}]({os.path.relpath(png, os.path.dirname(os.path.abspath(a.results)))})", ""]
    with open(a.results, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.results}")


if __name__ == "__main__":
    main()
