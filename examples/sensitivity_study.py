#!/usr/bin/env python3
"""Parameter sensitivity of the generated stockinette along s_x (`docs/python.md`, "Example: sensitivity study").

Ψ̄(s_x) of the generated pattern (as `hylc solve stockinette` uses it, not its C1 reference state) and its
sensitivities to the yarns' bending factor γ and contact stiffness k_c, from the envelope theorem
(`Solution.parameter_derivatives()`), along the s_x range of the sampling plan ([−0.6, 0.96]; two warm-started
chains from s_x = 0, as `hylc sample` walks a 1D range). At a few strains the derivatives are checked against
central differences of re-solved Ψ̄ (relative parameter step 1e-4), drawn as open circles.

    pip install ./python matplotlib
    python examples/sensitivity_study.py [--out examples/sensitivity_study.png] [--step 0.02]

Prints one line per strain and the finite-difference check, and writes the figure (three panels: Ψ̄, γ ∂Ψ̄/∂γ and
k_c ∂Ψ̄/∂k_c, both in J/m² per unit ln θ, i.e. the change of Ψ̄ per relative change of the parameter).
"""

import argparse
import time
from pathlib import Path

import numpy as np

import hylc

PARAMS = ("bend_twist_factor", "contact_stiffness")
LABELS = {"bend_twist_factor": "γ ∂Ψ̄/∂γ (bending factor)", "contact_stiffness": "k_c ∂Ψ̄/∂k_c (contact stiffness)"}


def chain(problem, values):
    """Solve along `values` of s_x, each from the previous equilibrium; (s_x, Solution) of the converged ones."""
    out, prev = [], None
    for sx in values:
        s = problem.solve([sx, 0.0, 0.0], start=prev)
        if s.converged:
            out.append((sx, s))
            prev = s
        else:
            print(f"s_x = {sx:+.3f}: {s.status} after {s.steps} steps (skipped)")
    return out


def finite_difference(pattern, yarn, solution, sx, name, rel=1e-4):
    """θ ∂Ψ̄/∂θ by central differences of Ψ̄ re-solved from `solution` with θ scaled by 1 ± rel."""
    psi = []
    for sign in (1.0, -1.0):
        y = dict(yarn)
        y[name] = yarn[name] * (1.0 + sign * rel)
        psi.append(hylc.MicroProblem(pattern, y).solve([sx, 0.0, 0.0], start=solution).psi)
    return (psi[0] - psi[1]) / (2.0 * rel)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).with_name("sensitivity_study.png"))
    ap.add_argument("--step", type=float, default=0.02, help="s_x spacing of the chains")
    a = ap.parse_args()
    t0 = time.perf_counter()
    pattern = hylc.generate("stockinette")
    yarn = hylc.yarn_defaults()
    problem = hylc.MicroProblem(pattern, yarn)
    up = np.arange(0.0, 0.96 + 1e-9, a.step)
    down = np.arange(-a.step, -0.6 - 1e-9, -a.step)
    solved = chain(problem, up) + chain(problem, down)
    solved.sort(key=lambda t: t[0])
    sx = np.array([t[0] for t in solved])
    psi = np.array([t[1].psi for t in solved])
    index = [hylc.PARAMETERS.index(n) for n in PARAMS]
    dtheta = np.array([t[1].parameter_derivatives()[index] for t in solved])
    relative = dtheta * np.array([yarn[n] for n in PARAMS])  # θ ∂Ψ̄/∂θ
    print(f"{'s_x':>7} {'psi':>12} {'g dpsi/dg':>12} {'kc dpsi/dkc':>12}")
    for x, p, r in zip(sx, psi, relative):
        print(f"{x:+7.3f} {p:12.5e} {r[0]:12.5e} {r[1]:12.5e}")

    # the envelope-theorem derivatives against finite differences at three strains
    checks = []
    for target in (-0.4, 0.2, 0.8):
        k = int(np.argmin(np.abs(sx - target)))
        for j, name in enumerate(PARAMS):
            fd = finite_difference(pattern, yarn, solved[k][1], sx[k], name)
            checks.append((sx[k], j, fd))
            err = abs(fd - relative[k, j]) / max(abs(fd), 1e-12)
            print(f"check s_x = {sx[k]:+.3f} {name}: envelope {relative[k, j]:.6e}, finite difference {fd:.6e}, "
                  f"relative difference {err:.1e}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(7, 9), sharex=True)
    axes[0].plot(sx, psi, "k.-")
    axes[0].set_ylabel("Ψ̄ (J/m²)")
    axes[0].set_yscale("log")
    axes[0].set_title(f"generated stockinette (no C1), s_a = s_y = 0, default yarn, {len(sx)} solves")
    for j, name in enumerate(PARAMS):
        ax = axes[j + 1]
        ax.plot(sx, relative[:, j], ".-", color=f"C{j}", label="envelope theorem")
        cx = [c[0] for c in checks if c[1] == j]
        cy = [c[2] for c in checks if c[1] == j]
        ax.plot(cx, cy, "o", mfc="none", ms=10, color="k", label="finite difference")
        ax.set_ylabel(LABELS[name] + "\n(J/m²)")
        ax.axhline(0.0, color="0.7", lw=0.8)
        ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("s_x")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out} ({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main()
