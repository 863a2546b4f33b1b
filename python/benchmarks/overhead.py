#!/usr/bin/env python3
"""The Python module's overheads (docs/python.md): import time, a batch ψ of 10⁵ strains against the plain Rust
loop over the same strains, and a micro solve against the CLI's solve time, all measured in one run.

    python python/benchmarks/overhead.py [--hylc target/release/hylc] [--repeat 5]
"""

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import hylc

ROOT = Path(__file__).resolve().parents[2]


def best(f, repeat):
    """The smallest wall time of `repeat` calls of f."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def import_time(repeat):
    """Wall time of `python -c "import hylc"` and of `python -c pass` (the interpreter alone)."""
    run = lambda code: subprocess.run([sys.executable, "-c", code], check=True)  # noqa: E731
    return best(lambda: run("import hylc"), repeat), best(lambda: run("pass"), repeat)


def batch_psi(repeat, n=100_000):
    rng = np.random.default_rng(7)
    z = np.zeros((n, 6))
    z[:, :3] = rng.uniform(-0.3, 0.6, (n, 3))
    z[:, 3:] = rng.uniform(-80.0, 80.0, (n, 3))
    m = hylc.Material.default()
    py = best(lambda: m.psi(z), repeat)
    rust = min(m._rust_loop_psi(z)[0] for _ in range(repeat))
    # the same values (summed in the same order)
    assert float(sum(m.psi(z).tolist())) == m._rust_loop_psi(z)[1]
    return py, rust


def solve(binary, repeat, pattern="stockinette", z=(0.3, 0.0, 0.1)):
    """Median wall time of `MicroProblem.solve` against the median solve time the CLI reports (`--json` "time")."""
    arg = ",".join(map(str, z))
    cli = []
    for _ in range(repeat):
        out = subprocess.run([binary, "solve", pattern, "--z", arg, "--json"], capture_output=True, text=True, check=True)
        cli.append(json.loads(out.stdout.splitlines()[-1])["time"])
    p = hylc.MicroProblem(pattern)
    py, inner = [], []
    for _ in range(repeat):
        t = time.perf_counter()
        s = p.solve(list(z))
        py.append(time.perf_counter() - t)
        inner.append(s.time)
    return statistics.median(py), statistics.median(inner), statistics.median(cli), s.steps


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hylc", default=str(ROOT / "target" / "release" / "hylc"))
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    imp, bare = import_time(a.repeat)
    print(f"import: python -c 'import hylc' {imp:.3f} s (python -c pass {bare:.3f} s)")
    py, rust = batch_psi(a.repeat)
    print(f"batch psi of 1e5 strains: Material.psi {py * 1e3:.1f} ms, Rust loop {rust * 1e3:.1f} ms, ratio {py / rust:.3f}")
    for z in [(0.3, 0.0, 0.1), (-0.3, 0.0, -0.3, 40.0, 0.0)]:
        wall, inner, cli, steps = solve(a.hylc, a.repeat, z=z)
        print(
            f"micro solve (stockinette, z = {','.join(map(str, z))}, {steps} Newton steps): Python wall "
            f"{wall * 1e3:.1f} ms (solver's own time {inner * 1e3:.1f} ms), CLI solve time {cli * 1e3:.1f} ms, "
            f"Python/CLI {100 * (wall / cli - 1):+.1f} %"
        )


if __name__ == "__main__":
    main()
