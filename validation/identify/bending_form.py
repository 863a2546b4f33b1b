#!/usr/bin/env python3
"""Which discrete curvature did the original store its rest curvatures in? (`docs/yarn-parameters.md`, "Bending
discretisation")

For every vertex of the five original patterns: the turning angle phi between its two edges at the stored state,
and the magnitude |RK| of the stored rest curvature (the `*RK` block of the .pyp file). If the rest shape is the
stored shape scaled in curvature (as it is for the weaves), |RK| / k(phi) is the same for every angle in the form
k the file was written in and drifts with phi in the others. Prints the median ratio per 10-degree bin for
k = 2 tan(phi/2) (our `tan` form), 2 sin(phi/2) (`sin`), sin(phi) and phi.

    validation/identify/bending_form.py [SHARED]       # SHARED defaults to ../shared

Pure Python (no packages). Exits 0 with a message when the original data are absent.
"""
import math
import os
import sys

FORMS = {
    "2tan(φ/2)": lambda p: 2 * math.tan(p / 2),
    "2sin(φ/2)": lambda p: 2 * math.sin(p / 2),
    "sin φ": math.sin,
    "φ": lambda p: p,
}
PATTERNS = ["basket", "satin", "slip_stitch_honeycomb", "stockinette", "cartridge_belt_rib"]


def blocks(path):
    """The numeric blocks of a .pyp file by name (`*Q # ...` -> "Q")."""
    out, cur = {}, None
    with open(path) as f:
        for line in f:
            if line.startswith("*"):
                cur = line.split()[0][1:]
                out[cur] = []
            elif line.strip() and cur:
                out[cur].append([float(v) for v in line.split()])
    return out


def angles_and_rest(path):
    b = blocks(path)
    px, py = b["pattern"][0][0], b["pattern"][0][1]
    q = b["Q"]
    out_edge, in_vertex = {}, {}
    for a, c, dx, dy in ([int(v) for v in r] for r in b["E"]):
        out_edge[a] = [q[c][0] + dx * px - q[a][0], q[c][1] + dy * py - q[a][1], q[c][2] - q[a][2]]
        in_vertex[c] = a
    rows = []
    for v in range(len(q)):
        e0, e1 = out_edge[in_vertex[v]], out_edge[v]
        dot = sum(x * y for x, y in zip(e0, e1))
        n0 = math.sqrt(sum(x * x for x in e0))
        n1 = math.sqrt(sum(x * x for x in e1))
        phi = math.acos(max(-1.0, min(1.0, dot / (n0 * n1))))
        rows.append((phi, math.hypot(*b["RK"][v][:2])))
    return rows


def main():
    shared = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "../../../shared")
    d = os.path.join(shared, "data/hylc2020/patterns")
    if not os.path.isdir(d):
        print(f"skipped: {d} not found")
        return
    print("median |RK| / k(φ) per turning-angle bin (n = vertices in the bin)")
    print(f"{'pattern':24s} {'φ (deg)':>8s} {'n':>4s} " + " ".join(f"{k:>10s}" for k in FORMS))
    for pat in PATTERNS:
        bins = {}
        for phi, rk in angles_and_rest(os.path.join(d, pat + ".pyp")):
            if phi > 1e-3:
                bins.setdefault(int(math.degrees(phi) // 10), []).append((phi, rk))
        for k in sorted(bins):
            rows = bins[k]
            med = []
            for f in FORMS.values():
                r = sorted(rk / f(phi) for phi, rk in rows)
                med.append(r[len(r) // 2])
            print(f"{pat:24s} {f'{10 * k}-{10 * k + 10}':>8s} {len(rows):4d} " + " ".join(f"{m:10.3f}" for m in med))


if __name__ == "__main__":
    main()
