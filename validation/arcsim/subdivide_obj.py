#!/usr/bin/env python3
"""Split every triangle of an OBJ into four at its edge midpoints (positions and texture coordinates alike).

Used by force_study.sh to rerun an ARCSim scene on a mesh with half the edge length: the original remeshes
adaptively, we keep a fixed mesh, and this measures how much a finer fixed mesh moves the handle forces.

    python3 subdivide_obj.py IN.obj OUT.obj
"""
import sys


def main(src, dst):
    verts, texs, faces = [], [], []
    with open(src) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif parts[0] == "vt":
                texs.append([float(x) for x in parts[1:3]])
            elif parts[0] == "f":
                if len(parts) != 4:
                    sys.exit(f"error: {src}: only triangles are supported, found a face with {len(parts) - 1}")
                corners = []
                for c in parts[1:]:
                    ids = c.split("/")
                    v = int(ids[0]) - 1
                    t = int(ids[1]) - 1 if len(ids) > 1 and ids[1] else None
                    corners.append((v, t))
                faces.append(corners)

    def midpoint(table, store, a, b):
        key = (min(a, b), max(a, b))
        if key not in table:
            store.append([(x + y) / 2 for x, y in zip(store[a], store[b])])
            table[key] = len(store) - 1
        return table[key]

    vmid, tmid, out = {}, {}, []
    for (v0, t0), (v1, t1), (v2, t2) in faces:
        m01 = midpoint(vmid, verts, v0, v1)
        m12 = midpoint(vmid, verts, v1, v2)
        m20 = midpoint(vmid, verts, v2, v0)
        if t0 is not None:
            n01 = midpoint(tmid, texs, t0, t1)
            n12 = midpoint(tmid, texs, t1, t2)
            n20 = midpoint(tmid, texs, t2, t0)
        else:
            n01 = n12 = n20 = None
        for tri in (
            [(v0, t0), (m01, n01), (m20, n20)],
            [(m01, n01), (v1, t1), (m12, n12)],
            [(m20, n20), (m12, n12), (v2, t2)],
            [(m01, n01), (m12, n12), (m20, n20)],
        ):
            out.append(tri)
    with open(dst, "w") as f:
        f.write(f"# {src} with every triangle split into four (subdivide_obj.py)\n")
        for v in verts:
            f.write("v %.9f %.9f %.9f\n" % tuple(v))
        for t in texs:
            f.write("vt %.9f %.9f\n" % tuple(t))
        for tri in out:
            f.write("f " + " ".join(f"{v + 1}/{t + 1}" if t is not None else f"{v + 1}" for v, t in tri) + "\n")
    print(f"{src}: {len(faces)} triangles -> {dst}: {len(out)} triangles, {len(verts)} vertices")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
