#!/usr/bin/env python3
"""The chain dJ/dθ = (dJ/dc)(dc/dΨ̄)(dΨ̄/dθ) against central differences of the whole pipeline.

For a generated pattern (default: the plain weave) and the quick plan: the reference state, the samples with
`--sensitivities`, the fit (`covering`), and `hylc gradient` of a quasi-static hanging cloth (J = its elastic
energy) with `--samples --yarn`, which gives dJ/dθ for every yarn parameter. Then, for the parameters chosen
(default: young, bend_twist_factor, contact_stiffness) and the relative steps chosen (default 1e-3), the same
pipeline at θ(1 ± h):

- `fixed`: the samples solved again on the base reference state (what the chain differentiates: the reference
  state held fixed), refitted, the scene re-solved;
- `full` (with --full): the reference state recomputed too (the whole pipeline), so that full − fixed measures
  what holding the reference fixed leaves out.

Per (parameter, h, variant): J(θ ± h θ), the central difference, the chain's value, their relative difference, and
how many samples changed branch between the two sides (|ΔΨ̄| / |Ψ̄| > 50 h, a jump far beyond the smooth change).
Writes a markdown table (--results, default docs/sensitivity-e2e-PATTERN.md) and the runs' folders under --out (resumable:
a finished stage is not repeated).

Usage:
  validation/sensitivity/end_to_end.py [--hylc target/release/hylc] [--out out/e2e] [--pattern plain]
      [--params young,bend_twist_factor,contact_stiffness] [--steps 1e-3] [--full] [--plan quick] [--prepare]
"""

import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def sh(hylc, args, ok=(0,)):
    t0 = time.time()
    p = subprocess.run([hylc] + [str(a) for a in args], capture_output=True, text=True)
    if p.returncode not in ok:
        sys.exit(f"end_to_end.py: hylc {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr[-2000:]}")
    return p.stdout, time.time() - t0


def scene_file(hylc, out):
    """A quasi-static hanging cloth (the built-in `hanging` on a 3 cm mesh, one step, tight tolerance)."""
    path = os.path.join(out, "hanging_static.json")
    if not os.path.exists(path):
        s = json.loads(sh(hylc, ["simulate", "hanging", "--print"])[0])
        s["mesh"]["rectangle"]["edge"] = 0.03
        s["quasi_static"] = True
        s["duration"] = s["dt"] = 0.1
        s["drag"] = 0.0
        s["solver"]["force_tol"] = 1e-11
        s["solver"]["max_newton"] = 200
        with open(path, "w") as f:
            json.dump(s, f, indent=1)
    return path


def stage(done, fn):
    """Run fn unless the file `done` exists."""
    if not os.path.exists(done):
        fn()
    return done


def pipeline(hylc, d, pattern, plan, yarn, reference=None, sensitivities=False):
    """reference (unless given) → samples → fit in folder d; returns the material's path and the sampling time."""
    os.makedirs(d, exist_ok=True)
    ref = reference or os.path.join(d, "reference.pyp")
    if reference is None:
        stage(ref, lambda: sh(hylc, ["reference", pattern, "--yarn", yarn, "--out", ref]))
    samples = os.path.join(d, "samples.jsonl")
    timing = os.path.join(d, "sample_seconds")

    def sample():
        flags = ["--sensitivities"] if sensitivities else []
        _, t = sh(hylc, ["sample", ref, "--plan", plan, "--out", samples, "--crossings", "reject", "--yarn", yarn]
                  + flags, ok=(0, 3))
        with open(timing, "w") as f:
            f.write(f"{t}\n")

    stage(timing, sample)
    material = os.path.join(d, "material.json")
    stage(material, lambda: sh(hylc, ["fit", samples, "--out", material, "--no-plots"]))
    return material, samples, float(open(timing).read())


def observable(hylc, scene, material, out, extra=()):
    stdout, t = sh(hylc, ["gradient", scene, "--observable", "energy", "--material", material, "--out", out,
                          "--quiet"] + list(extra))
    with open(os.path.join(out, "gradient.json")) as f:
        return json.load(f), t


def psi_of(samples):
    out = {}
    with open(samples) as f:
        for line in f:
            r = json.loads(line)
            if r.get("psi") is not None:
                out[r["id"].split("-")[-1]] = r["psi"]
    return out


def switches(a, b, h):
    pa, pb = psi_of(a), psi_of(b)
    return sum(1 for k in pa if k in pb and abs(pa[k] - pb[k]) > 50 * h * max(abs(pa[k]), abs(pb[k]), 1e-12))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hylc", default=os.path.join(ROOT, "target", "release", "hylc"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "e2e"))
    ap.add_argument("--pattern", default="plain")
    ap.add_argument("--plan", default="quick")
    ap.add_argument("--params", default="young,bend_twist_factor,contact_stiffness")
    ap.add_argument("--steps", default="1e-3")
    ap.add_argument("--full", action="store_true", help="also recompute the reference state on each side")
    ap.add_argument("--results", default=None, help="default: docs/sensitivity-e2e-PATTERN.md")
    ap.add_argument("--prepare", action="store_true", help="only sample and fit every side (no gradient)")
    a = ap.parse_args()
    a.results = a.results or os.path.join(ROOT, "docs", f"sensitivity-e2e-{a.pattern}.md")
    hylc, out = a.hylc, os.path.join(a.out, a.pattern)
    os.makedirs(out, exist_ok=True)
    yarn0 = json.loads(sh(hylc, ["yarn"])[0])
    base_yarn = os.path.join(out, "yarn.json")
    with open(base_yarn, "w") as f:
        json.dump(yarn0, f)
    scene = scene_file(hylc, out)
    base = os.path.join(out, "base")
    material, samples, t_sample = pipeline(hylc, base, a.pattern, a.plan, base_yarn, sensitivities=True)
    # every side's samples and fit first (they need no gradient), then the scene on each
    runs = []
    for name in a.params.split(","):
        for h in [float(s) for s in a.steps.split(",")]:
            for variant in ["fixed"] + (["full"] if a.full else []):
                sides = []
                for sign in (+1, -1):
                    y = dict(yarn0)
                    y[name] = yarn0[name] * (1 + sign * h)
                    d = os.path.join(out, f"{name}_{h:g}_{variant}_{'p' if sign > 0 else 'm'}")
                    os.makedirs(d, exist_ok=True)
                    yf = os.path.join(d, "yarn.json")
                    with open(yf, "w") as f:
                        json.dump(y, f)
                    ref = os.path.join(base, "reference.pyp") if variant == "fixed" else None
                    m, s, _ = pipeline(hylc, d, a.pattern, a.plan, yf, reference=ref)
                    print(f"{os.path.basename(d)}: sampled and fitted", flush=True)
                    sides.append((d, m, s))
                runs.append((name, h, variant, sides))
    if a.prepare:
        return
    g, t_grad = observable(hylc, scene, material, os.path.join(base, "gradient"),
                           ["--samples", samples, "--yarn", base_yarn])
    chain = g["yarn"]
    rows = []
    for name, h, variant, sides in runs:
        js = [observable(hylc, scene, m, os.path.join(d, "gradient"))[0]["value"] for d, m, _ in sides]
        diff = (js[0] - js[1]) / (2 * h * yarn0[name])
        rel = abs(chain[name] - diff) / max(abs(diff), 1e-300)
        rows.append((name, h, variant, js[0], js[1], diff, chain[name], rel, switches(sides[0][2], sides[1][2], h)))
        print(f"{name} h={h:g} {variant}: difference {diff:.6e}, chain {chain[name]:.6e}, relative {rel:.2e}",
              flush=True)
    lines = [
        "# The yarn chain against differences of the whole pipeline",
        "",
        f"Written by `validation/sensitivity/end_to_end.py --pattern {a.pattern} --steps {a.steps}"
        f"{' --full' if a.full else ''}`: generated `{a.pattern}`, the `{a.plan}` plan, the "
        "`covering` fit, a quasi-static hanging cloth (3 cm mesh), J its elastic energy (J). `fixed`: the samples "
        "re-solved on the base reference state; `full`: the reference state recomputed too. Branch switches: "
        "samples whose Ψ̄ moved by more than 50 h relative between the two sides.",
        "",
        f"J = {g['value']:.6e} J; sampling with sensitivities {t_sample:.1f} s, gradient with the chain "
        f"{t_grad:.1f} s (the whole `hylc gradient`).",
        "",
        "| parameter | h | variant | J(θ(1+h)) | J(θ(1−h)) | difference dJ/dθ | chain dJ/dθ | relative | branch switches |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        lines.append(f"| {r[0]} | {r[1]:g} | {r[2]} | {r[3]:.8e} | {r[4]:.8e} | {r[5]:.6e} | {r[6]:.6e} | "
                     f"{r[7]:.2e} | {r[8]} |")
    with open(a.results, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {a.results}")


if __name__ == "__main__":
    main()
