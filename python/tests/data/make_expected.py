"""Regenerate the stored expectations of the Python tests from the command line (run by hand, not by pytest):

    cargo build --release && python3 python/tests/data/make_expected.py [target/release/hylc]

Writes `expected.json` (the CLI's material values, messages and reference-state numbers) and the `.pyp` files
the CLI writes (generated patterns, the reference state), beside this script. The tests compare the Python module
with these, so a change of the library's results shows up as a diff of these files."""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
BIN = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "release" / "hylc"


def cli(*args, check=True):
    p = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise SystemExit(f"hylc {' '.join(map(str, args))}: {p.stderr}")
    return p


def strains(n, seed=1):
    """The strains of test_material.py."""
    rng = np.random.default_rng(seed)
    z = np.zeros((n, 6))
    z[:, 0] = rng.uniform(-0.2, 0.5, n)
    z[:, 1] = rng.uniform(-0.3, 0.3, n)
    z[:, 2] = rng.uniform(-0.2, 0.5, n)
    z[:, 3:] = rng.uniform(-50, 50, (n, 3))
    return z


def main():
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        z = strains(5)
        args = ["material", "default", "--json"]
        for row in z:
            args += ["--z", ",".join(repr(float(v)) for v in row)]
        records = [json.loads(line) for line in cli(*args).stdout.splitlines() if line.startswith("{")]
        out["material_default"] = {"z": z.tolist(), "psi": [r["psi"] for r in records],
                                   "grad": [r["grad"] for r in records], "hess": [r["hess"] for r in records]}
        cli("material", "default", "--write", tmp / "m.json")
        m = json.loads((tmp / "m.json").read_text())
        out["material_default"]["keys"] = sorted(m)
        out["material_default"]["density"] = m["density"]
        bad = tmp / "bad.json"
        bad.write_text('{"density": 0.2}')
        err = cli("material", bad, "--z", "0,0,0,0,0,0", check=False).stderr.strip()
        out["bad_material_error"] = err.replace(str(bad), "{path}")
        out["generate_jersey_error"] = cli("generate", "jersey", check=False).stderr.strip()
        badpyp = tmp / "bad.pyp"
        badpyp.write_text("*not a pattern\n")
        out["bad_pyp_error"] = cli("pattern", badpyp, check=False).stderr.strip().replace(str(badpyp), "{path}")
        for name, extra in [("plain", []), ("twill", ["--n", "3"]), ("stockinette", [])]:
            cli("generate", name, *extra, "--out", HERE / f"{name}.pyp")
        cli("reference", "plain", "--out", HERE / "plain.reference.pyp", "--json", tmp / "ref.json")
        ref = json.loads((tmp / "ref.json").read_text())
        out["reference_plain"] = {"psi": ref["psi"], "periods_out": ref["periods_out"]}
        out["yarn_defaults_text"] = cli("yarn").stdout
    (HERE / "expected.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
