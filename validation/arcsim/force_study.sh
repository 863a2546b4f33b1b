#!/usr/bin/env bash
# Where the handle force of the original's tests/2D/conf/stock_stretchX.json differs from the published one
# (0.83, 1.70, 2.97, 4.23 N at t = 0.1, 0.2, 0.3, 0.4 s, the original simulator with
# remeshing): the scene converted once (`hylc simulate --print`), then run to 0.4 s in variants that each change
# one thing against `base` (our defaults for an ARCSim scene: one implicit step per frame, 1/60 s, fixed mesh):
#   dt600   ten times smaller step (1/600 s; the original takes 80 linearised substeps per frame)
#   nodamp  no stiffness-proportional damping (the scene has damping 0.001 s)
#   hard    handles as hard constraints instead of springs of 1e5 N/m per vertex
#   fine    every triangle of hylc_square.obj split into four (20 672 triangles; the original refines adaptively)
#   rect    our regular rectangle mesh of the same size and resolution (0.3 m, edge 6 mm: 5 202 triangles)
#   coarse  the rectangle mesh at twice the edge (12 mm: 1 250 triangles)
# Prints one table row per variant: |F_x| (mean of the two handles) at the four times and the difference to the
# published value (the force along the stretch). Runs stay in $OUT/<variant>/ and are reused unless RERUN=1.
#
#   cargo build --release && validation/arcsim/force_study.sh            # all variants (hours on 2 cores)
#   validation/arcsim/force_study.sh base dt600                          # some of them
#   SCENE=2D/conf/basket_stretchX validation/arcsim/force_study.sh base  # another scene (no published curve)
set -uo pipefail
cd "$(dirname "$0")/../.."
HYLC=${HYLC:-target/release/hylc}
D=${HYLC_SHARED:-../shared}/data/arcsim-hylc
SCENE=${SCENE:-2D/conf/stock_stretchX}
OUT=${OUT:-out/force_study/$(basename "$SCENE")}
DURATION=${DURATION:-0.4}
src="$D/tests/$SCENE.json"
if [ ! -f "$src" ]; then echo "skipped: $src not found (set HYLC_SHARED)"; exit 0; fi
if [ ! -x "$HYLC" ]; then echo "error: $HYLC not found (cargo build --release, or set HYLC)"; exit 2; fi
variants=("$@")
if [ ${#variants[@]} -eq 0 ]; then variants=(base dt600 nodamp hard fine); fi
mkdir -p "$OUT"
"$HYLC" simulate "$src" --print > "$OUT/converted.json" 2> "$OUT/converted.stderr" || {
  echo "error: converting $src failed:"; cat "$OUT/converted.stderr"; exit 2; }
for v in "${variants[@]}"; do
  dir="$OUT/$v"
  if [ "${RERUN:-0}" != 1 ] && [ -f "$dir/exit_code" ]; then continue; fi
  mkdir -p "$dir"
  python3 - "$OUT/converted.json" "$(dirname "$src")" "$v" "$DURATION" "$dir" <<'PY' || exit 2
import json, os, subprocess, sys
conv, here, variant, duration, out = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5]
s = json.load(open(conv))
# the converted scene's paths are relative to the ARCSim file's folder: make them absolute
s["material"] = os.path.abspath(os.path.join(here, s["material"]))
s["mesh"]["obj"]["path"] = os.path.abspath(os.path.join(here, s["mesh"]["obj"]["path"]))
s["duration"] = duration
s["output"] = {"obj_every": 6}
if variant == "dt600":
    s["dt"] = s["dt"] / 10
    s["output"] = {"obj_every": 60}
elif variant == "nodamp":
    s["damping"] = 0.0
elif variant == "hard":
    s["handle_stiffness"] = None
elif variant == "fine":
    fine = os.path.join(out, "mesh_fine.obj")
    subprocess.run([sys.executable, "validation/arcsim/subdivide_obj.py", s["mesh"]["obj"]["path"], fine], check=True)
    s["mesh"]["obj"]["path"] = os.path.abspath(fine)
elif variant in ("rect", "coarse"):
    # the handlebar boxes are in the rest layout [0, 0.3]², which the rectangle mesh shares
    s["mesh"] = {"rectangle": {"width": 0.3, "height": 0.3, "edge": 0.006 if variant == "rect" else 0.012}}
elif variant != "base":
    sys.exit(f"error: unknown variant {variant!r} (base, dt600, nodamp, hard, fine, rect, coarse)")
json.dump(s, open(os.path.join(out, "scene.json"), "w"), indent=1)
PY
  start=$(date +%s.%N)
  "$HYLC" simulate "$dir/scene.json" --quiet --out "$dir" > "$dir/stdout.txt" 2> "$dir/stderr.txt"
  echo $? > "$dir/exit_code"
  echo "$(date +%s.%N) - $start" | bc > "$dir/wall_seconds"
done
python3 - "$OUT" "${variants[@]}" <<'PY'
import json, os, sys
out, variants = sys.argv[1], sys.argv[2:]
axis = 1 if out.rstrip("/").endswith("Y") else 0  # the stretch direction: |F_x| of a stretchX scene
published = {0.1: 0.83, 0.2: 1.70, 0.3: 2.97, 0.4: 4.23}
print("| variant | exit | wall (s) | Newton iterations | substeps | " + " | ".join(f"t = {t} s" for t in published) + " |")
print("| --- | ---: | ---: | ---: | ---: | " + " | ".join("---:" for _ in published) + " |")
print("| original (published, remeshing) | | | | | " + " | ".join(f"{f:.3f}" for f in published.values()) + " |")
for v in variants:
    d = os.path.join(out, v)
    try:
        rs = [json.loads(l) for l in open(os.path.join(d, "log.jsonl"))]
    except OSError:
        print(f"| {v} | (no log) | | | | " + " | ".join("" for _ in published) + " |")
        continue
    code = open(os.path.join(d, "exit_code")).read().strip()
    cells = []
    for t, ref in published.items():
        r = min(rs, key=lambda r: abs(r["time"] - t))
        if abs(r["time"] - t) > 0.01:
            cells.append("")
            continue
        f = [abs(hf[1][axis]) for hf in r["handle_forces"]]
        m = sum(f) / len(f)
        cells.append(f"{m:.3f} ({100 * (m - ref) / ref:+.1f} %)")
    print(f"| {v} | {code} | {sum(r['wall'] for r in rs):.0f} | {sum(r['newton'] for r in rs)} | "
          f"{sum(r['substeps'] for r in rs)} | " + " | ".join(cells) + " |")
PY
