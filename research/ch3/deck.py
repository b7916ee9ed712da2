"""What the CalculiX decks of research/ch3 share (issue 16): twenty-node
hexahedral meshes of unions of axis-aligned boxes, the deck's element and
node-set lines, running ccx on one core, and reading the frequencies back.

The algorithm is that of flexmb's built-in mesher (`Mesh::boxes` in
crates/superelement/src/solid.rs), written again here so that the CalculiX
reference and the superelement are built on the same elements: grid lines at
every box bound, each interval cut into ceil(length / h - 1e-9) equal
elements, and a cell kept (with the first box's material) when its centre
lies inside a box. Node order within an element is CalculiX's C3D20 order
(corners 1-4 at the bottom, 5-8 at the top, then the bottom, top and
vertical mid-side nodes), the order of HEX20_LOCAL in solid.rs.
"""
import math
import os
import subprocess

# (a, b, c) in {0, 1, 2}^3 per element node, as HEX20_LOCAL in solid.rs
HEX20_LOCAL = [
    (0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0),
    (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2),
    (1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0),
    (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
    (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1),
]


def grid_lines(bounds, h):
    b = sorted(bounds)
    span = b[-1] - b[0]
    d = [b[0]]
    for v in b[1:]:
        if abs(v - d[-1]) > 1e-12 * span:
            d.append(v)
    out = [d[0]]
    for a, c in zip(d, d[1:]):
        n = max(1, math.ceil((c - a) / h - 1e-9))
        out += [a + (c - a) * i / n for i in range(1, n + 1)]
    return out


def boxes(blocks, h, first_node=1, first_element=1):
    """blocks: [((xmin, ymin, zmin), (xmax, ymax, zmax), tag)], h: (hx, hy, hz).
    Returns (nodes {label: (x, y, z)}, elements [(label, [20 labels], tag)])."""
    lines = [grid_lines([bl[0][d] for bl in blocks] + [bl[1][d] for bl in blocks], h[d]) for d in range(3)]
    nc = [len(l) - 1 for l in lines]
    cells = []
    for k in range(nc[2]):
        for j in range(nc[1]):
            for i in range(nc[0]):
                c = [0.5 * (lines[0][i] + lines[0][i + 1]), 0.5 * (lines[1][j] + lines[1][j + 1]),
                     0.5 * (lines[2][k] + lines[2][k + 1])]
                for lo, hi, tag in blocks:
                    if all(lo[d] < c[d] < hi[d] for d in range(3)):
                        cells.append(((i, j, k), tag))
                        break

    def coord(d, q):
        i = q // 2
        return lines[d][i] if q % 2 == 0 else 0.5 * (lines[d][i] + lines[d][i + 1])

    keys = sorted({(2 * c[0] + a, 2 * c[1] + b, 2 * c[2] + e) for c, _ in cells for a, b, e in HEX20_LOCAL},
                  key=lambda q: (q[2], q[1], q[0]))
    label = {q: first_node + n for n, q in enumerate(keys)}
    nodes = {label[q]: (coord(0, q[0]), coord(1, q[1]), coord(2, q[2])) for q in keys}
    elements = []
    for n, (c, tag) in enumerate(cells):
        elements.append((first_element + n,
                         [label[(2 * c[0] + a, 2 * c[1] + b, 2 * c[2] + e)] for a, b, e in HEX20_LOCAL], tag))
    return nodes, elements


def element_lines(elements, etype, elset):
    out = [f"*ELEMENT,TYPE={etype},ELSET={elset}"]
    for e, ns, _ in elements:
        out.append(f"{e}," + ",".join(map(str, ns[:15])) + ",")
        out.append(",".join(map(str, ns[15:])))
    return out


def nset_lines(name, labels):
    out = [f"*NSET,NSET={name}"]
    labels = sorted(labels)
    out += [",".join(map(str, labels[i:i + 16])) for i in range(0, len(labels), 16)]
    return out


def on_plane(nodes, d, v, tol=1e-9):
    return [n for n, p in nodes.items() if abs(p[d] - v) <= tol]


def parse_frequencies(path):
    """Frequencies (Hz) of each *FREQUENCY step in a .dat file, in order."""
    out = []
    lines = open(path).read().splitlines()
    i = 0
    while i < len(lines):
        if "E I G E N V A L U E   O U T P U T" in lines[i]:
            fs = []
            j = i + 1
            while j < len(lines) and "P A R T I C I P" not in lines[j] and "E I G E N V A L U E    N U M B E R" not in lines[j]:
                v = lines[j].split()
                if len(v) == 5 and v[0].isdigit():
                    fs.append(float(v[3]))
                j += 1
            out.append(fs)
            i = j
            continue
        i += 1
    return out


def run_ccx(job, out):
    """Runs `ccx -i job` in the folder `out` on one core at low priority,
    keeps its output in job.log and stops the script if ccx failed."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    r = subprocess.run(["nice", "-n", "10", "ccx", "-i", job], cwd=out, env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    open(os.path.join(out, job + ".log"), "w").write(r.stdout)
    if "Job finished" not in r.stdout:
        raise SystemExit(f"ccx failed, see {out}/{job}.log")
