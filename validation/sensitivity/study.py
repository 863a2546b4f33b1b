#!/usr/bin/env python3
"""Normalised sensitivities (θ/J) dJ/dθ of three cloth observables to the six yarn parameters, for the original
patterns with their identified yarn parameters.

Per pattern (`../shared/data/hylc2020/patterns/<name>.pyp`, yarn `validation/identify/<name>/identified.yarn.json`):
the quick plan sampled with `--sensitivities` (`--crossings reject`), the `covering` fit, then `hylc gradient …
--samples` on
- `sag`: the built-in `drape-x` made quasi-static (one load step, 3 cm mesh), J = −(centre of mass z) (the sag);
- `energy`: the same equilibrium's elastic energy;
- `force`: the built-in `stretch-x` (dynamic, 2.5 cm mesh), J = the right handle's x reaction at 0.3 s, through
  the trajectory adjoint.
Each dJ/dθ holds the reference state fixed (the pattern as the original gives it). Writes a markdown table
(--results, default docs/sensitivity-study.md) and a bar chart (docs/sensitivity-study.png; matplotlib is installed
with pip when missing). Resumable: a pattern's samples and fit are kept under --out (default out/sensitivity_study).

Usage: validation/sensitivity/study.py [--hylc target/release/hylc] [--patterns basket,satin,...]
"""

import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "..", "shared", "data", "hylc2020", "patterns")
PATTERNS = ["basket", "satin", "slip_stitch_honeycomb", "stockinette", "cartridge_belt_rib"]
PARAMS = ["young", "shear", "bend_twist_factor", "contact_stiffness", "contact_radius_factor", "radius"]


def sh(hylc, args, ok=(0,)):
    p = subprocess.run([hylc] + [str(a) for a in args], capture_output=True, text=True)
    if p.returncode not in ok:
        return None, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}"
    return p.stdout, None


def scenes(hylc, out):
    drape = json.loads(sh(hylc, ["simulate", "drape-x", "--print"])[0])
    drape["mesh"]["rectangle"]["edge"] = 0.03
    drape.update(quasi_static=True, duration=0.1, dt=0.1, drag=0.0)
    drape["solver"].update(force_tol=1e-10, max_newton=200)
    stretch = json.loads(sh(hylc, ["simulate", "stretch-x", "--print"])[0])
    stretch["mesh"]["rectangle"]["edge"] = 0.025
    stretch["duration"] = 0.3
    paths = []
    for name, s in [("drape", drape), ("stretch", stretch)]:
        p = os.path.join(out, f"{name}.json")
        with open(p, "w") as f:
            json.dump(s, f)
        paths.append(p)
    return paths


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hylc", default=os.path.join(ROOT, "target", "release", "hylc"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "sensitivity_study"))
    ap.add_argument("--patterns", default=",".join(PATTERNS))
    ap.add_argument("--results", default=os.path.join(ROOT, "docs", "sensitivity-study.md"))
    ap.add_argument("--plot", default=os.path.join(ROOT, "docs", "sensitivity-study.png"))
    a = ap.parse_args()
    if not os.path.isdir(DATA):
        sys.exit(f"study.py: {DATA} not found (the original patterns); nothing to do")
    os.makedirs(a.out, exist_ok=True)
    drape, stretch = scenes(a.hylc, a.out)
    results = {}
    for pat in a.patterns.split(","):
        d = os.path.join(a.out, pat)
        os.makedirs(d, exist_ok=True)
        yarn = os.path.join(ROOT, "validation", "identify", pat, "identified.yarn.json")
        samples = os.path.join(d, "samples.jsonl")
        material = os.path.join(d, "material.json")
        t0 = time.time()
        if not os.path.exists(material):
            _, err = sh(a.hylc, ["sample", os.path.join(DATA, pat + ".pyp"), "--plan", "quick", "--out", samples,
                                 "--crossings", "reject", "--sensitivities", "--yarn", yarn], ok=(0, 3))
            if err:
                sys.exit(f"study.py: {pat}: sample: {err}")
            _, err = sh(a.hylc, ["fit", samples, "--out", material, "--no-plots"])
            if err:
                sys.exit(f"study.py: {pat}: fit: {err}")
        t_material = time.time() - t0
        # the yarn parameters the samples were solved with (the pattern's radius replaces the yarn file's)
        with open(os.path.join(d, "samples.meta.json")) as f:
            used = json.load(f)["yarn"]
        yarn = os.path.join(d, "yarn.json")
        with open(yarn, "w") as f:
            json.dump(used, f)
        row = {}
        for key, scene, obs, extra, sign in [
            ("sag", drape, "com-z", [], -1.0),
            ("energy", drape, "energy", [], 1.0),
            ("force", stretch, "handle-force:right:x", ["--at", "0.3"], 1.0),
        ]:
            g_out = os.path.join(d, key)
            _, err = sh(a.hylc, ["gradient", scene, "--observable", obs, "--material", material, "--samples",
                                 samples, "--yarn", yarn, "--out", g_out, "--quiet"] + extra)
            if err:
                row[key] = {"error": err}
                print(f"{pat} {key}: {err}", flush=True)
                continue
            with open(os.path.join(g_out, "gradient.json")) as f:
                g = json.load(f)
            y = json.load(open(yarn))
            j = sign * g["value"]
            row[key] = {"J": j, "normalised": {p: y[p] * sign * g["yarn"][p] / j for p in PARAMS},
                        "kinks": len(g["yarn_chain"]["kinks"])}
            print(f"{pat} {key}: J = {j:.4e}, " + ", ".join(f"{p} {v:+.3f}" for p, v in row[key]["normalised"].items()),
                  flush=True)
        row["seconds"] = time.time() - t0
        row["material_seconds"] = t_material
        results[pat] = row
    write(a, results)


def write(a, results):
    lines = [
        "# Sensitivities of cloth observables to the yarn parameters",
        "",
        "Written by `validation/sensitivity/study.py`: the original patterns with their identified yarn parameters "
        "(`validation/identify/<pattern>/identified.yarn.json`, the radius the pattern's), the quick plan sampled with `--sensitivities`, the "
        "`covering` fit; normalised sensitivities (θ/J) dJ/dθ (a 1 % change of θ changes J by about that many per "
        "cent), the reference state (the original's pattern) held fixed. `sag`: −(centre of mass z) of `drape-x` "
        "made quasi-static (3 cm mesh); `energy`: its elastic energy; `force`: the right handle's x reaction of "
        "`stretch-x` (2.5 cm mesh) at 0.3 s, through the trajectory adjoint.",
        "",
        "| pattern | observable | J | " + " | ".join(PARAMS) + " | fit kinks |",
        "| --- | --- | ---: | " + " | ".join("---:" for _ in PARAMS) + " | ---: |",
    ]
    for pat, row in results.items():
        for key in ["sag", "energy", "force"]:
            r = row.get(key, {})
            if "error" in r:
                reason = r["error"].removeprefix("error: ")
                if "did not converge" in reason:
                    reason = "the step did not converge (Newton, even with the step halved 6 times)"
                lines.append(f"| {pat} | {key} | no gradient: {reason} |" + " |" * (len(PARAMS) + 1))
                continue
            lines.append(f"| {pat} | {key} | {r['J']:.4e} | " + " | ".join(f"{r['normalised'][p]:+.3f}" for p in PARAMS)
                         + f" | {r['kinks']} |")
    with open(a.results, "w") as f:
        f.write("\n".join(lines) + "\n")
    try:
        import matplotlib
    except ImportError:
        subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "matplotlib"], check=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5), sharey=False)
    width = 0.8 / max(1, len(results))
    for ax, key in zip(axes, ["sag", "energy", "force"]):
        for i, (pat, row) in enumerate(results.items()):
            r = row.get(key, {})
            if "normalised" not in r:
                continue
            xs = [k + (i - (len(results) - 1) / 2) * width for k in range(len(PARAMS))]
            ax.bar(xs, [r["normalised"][p] for p in PARAMS], width, label=pat, color=f"C{i}")
        ax.set_xticks(range(len(PARAMS)))
        ax.set_xticklabels(["Y", "G", "γ", "k_c", "f", "r"])
        ax.axhline(0, color="k", lw=0.5)
        ax.set_title({"sag": "drape sag", "energy": "drape elastic energy", "force": "stretch handle force, 0.3 s"}[key])
        ax.set_ylabel("(θ/J) dJ/dθ")
    handles = [plt.Rectangle((0, 0), 1, 1, color=f"C{i}") for i in range(len(results))]
    axes[0].legend(handles, list(results), fontsize=8)
    fig.tight_layout()
    fig.savefig(a.plot, dpi=110)
    print(f"wrote {a.results} and {a.plot}")


if __name__ == "__main__":
    main()
