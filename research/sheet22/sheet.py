#!/usr/bin/env python3
"""Single sheet flexure: CalculiX C3D20R solid against flexmb beams (issue 22, item 2).

A cantilever sheet, clamped at y = 0, free at y = L, loaded at its free end by
a force P along x (fixed direction), which bends it about its weak axis (z).
Axes as in fixtures/scenes/straight_guidance_spatial.ron: length along y,
height b along z, thickness t along x.

For each load level the solid deck has an NLGEOM *STATIC step followed by a
*FREQUENCY perturbation step (the eigenproblem of the tangent stiffness at the
deformed, prestressed state). The out-of-plane modes (z-translation, torsion)
are told from the in-plane ones by their participation factors: the deformed
sheet is symmetric about z = 0, so in-plane modes have exactly zero z,
x-rotation and y-rotation participation.

The beam side is a flexmb scene with one chain of n spatial beams, swept over
the same load levels (`flexmb sweep --over load`).

Usage (from the repository root):
  python3 research/sheet22/sheet.py solid --t 0.001 --mat nu0 --nl 100 --nh 12 --loads 0,1,2 --out DIR
  python3 research/sheet22/sheet.py beam  --t 0.001 --mat nu0 --n 40 --loads 0,1,2 --out DIR
Both print CSV rows: case,P,tip_x,tip_y,mode,f_Hz,kind (kind = in / out).

Materials (--mat):
  nu0   : nu = 0 with G = E/2.6 (orthotropic *ELASTIC,TYPE=ENGINEERING CONSTANTS
          with all E equal, all nu zero, all G = E/2.6). This is the issue's
          solid: no Poisson coupling, and the same E and G as the flexmb beam
          with nu = 0.3 (flexmb takes G = E/(2(1+nu)) = E/2.6). So any
          difference is kinematic (beam vs continuum), not material.
  nu0g2 : isotropic nu = 0 (G = E/2); beam with nu = 0.
  nu03  : isotropic nu = 0.3, the physical steel; beam with nu = 0.3.
"""
import argparse
import os
import re
import subprocess
import sys

E = 2.1e11
RHO = 7600.0
FLEXMB = os.environ.get("FLEXMB", "/work/main/target/release/flexmb")


def mesh(L, b, t, nl, nh, nt):
    """Structured C3D20 mesh. Returns nodes {id: (x,y,z)}, elements [(id, [20 ids])]
    and index helpers. Grid indices (i along y, j along z, k along x) at half
    element spacing; 20-node elements leave face and body centres unused."""
    NI, NJ, NK = 2 * nl + 1, 2 * nh + 1, 2 * nt + 1
    nid = {}
    nodes = {}

    def used(i, j, k):
        odd = (i % 2) + (j % 2) + (k % 2)
        return odd <= 1

    c = 0
    for i in range(NI):
        for j in range(NJ):
            for k in range(NK):
                if used(i, j, k):
                    c += 1
                    nid[(i, j, k)] = c
                    nodes[c] = (-t / 2 + t * k / (NK - 1), L * i / (NI - 1), -b / 2 + b * j / (NJ - 1))
    elems = []
    e = 0
    # local (a, b, c) = (y, z, x): right-handed because y x z = x
    for ei in range(nl):
        for ej in range(nh):
            for ek in range(nt):
                i0, j0, k0 = 2 * ei, 2 * ej, 2 * ek
                P = lambda a, bb, cc: nid[(i0 + a, j0 + bb, k0 + cc)]
                corners = [P(0, 0, 0), P(2, 0, 0), P(2, 2, 0), P(0, 2, 0),
                           P(0, 0, 2), P(2, 0, 2), P(2, 2, 2), P(0, 2, 2)]
                mids = [P(1, 0, 0), P(2, 1, 0), P(1, 2, 0), P(0, 1, 0),
                        P(1, 0, 2), P(2, 1, 2), P(1, 2, 2), P(0, 1, 2),
                        P(0, 0, 1), P(2, 0, 1), P(2, 2, 1), P(0, 2, 1)]
                e += 1
                elems.append((e, corners + mids))
    return nodes, elems, nid, (NI, NJ, NK)


def tip_weights(nid, dims, nh, nt):
    """Consistent nodal weights of a uniform traction on the face y = L
    (8-node serendipity faces: corners -1/12, mid-sides 1/3 of the face load)."""
    NI, NJ, NK = dims
    w = {}
    i = NI - 1
    for ej in range(nh):
        for ek in range(nt):
            j0, k0 = 2 * ej, 2 * ek
            share = 1.0 / (nh * nt)
            for (a, c2, f) in [(0, 0, -1 / 12), (2, 0, -1 / 12), (2, 2, -1 / 12), (0, 2, -1 / 12),
                               (1, 0, 1 / 3), (2, 1, 1 / 3), (1, 2, 1 / 3), (0, 1, 1 / 3)]:
                n = nid[(i, j0 + a, k0 + c2)]
                w[n] = w.get(n, 0.0) + f * share
    return w


def material_cards(mat):
    if mat == "nu0":
        G = E / 2.6
        return ("*ELASTIC,TYPE=ENGINEERING CONSTANTS\n"
                f"{E:.6e},{E:.6e},{E:.6e},0.,0.,0.,{G:.6e},{G:.6e}\n{G:.6e}\n")
    if mat == "nu0g2":
        return f"*ELASTIC\n{E:.6e},0.0\n"
    if mat == "nu03":
        return f"*ELASTIC\n{E:.6e},0.3\n"
    raise SystemExit(f"unknown material {mat}")


def write_deck(path, L, b, t, nl, nh, nt, mat, loads, nmodes, incs, clamp_kind="full", edges_out=False):
    nodes, elems, nid, dims = mesh(L, b, t, nl, nh, nt)
    NI, NJ, NK = dims
    clamp = [n for (i, j, k), n in nid.items() if i == 0]
    tipc = nid[(NI - 1, (NJ - 1) // 2, (NK - 1) // 2)]
    w = tip_weights(nid, dims, nh, nt)
    out = ["*HEADING", f"sheet L={L} b={b} t={t} mesh {nl}x{nh}x{nt} C3D20R mat={mat}", "*NODE"]
    out += [f"{n},{x:.9e},{y:.9e},{z:.9e}" for n, (x, y, z) in nodes.items()]
    out.append("*ELEMENT,TYPE=C3D20R,ELSET=SHEET")
    for e, ns in elems:
        # at most 16 entries per line in ccx input
        out.append(f"{e}," + ",".join(map(str, ns[:15])) + ",")
        out.append(",".join(map(str, ns[15:])))
    out.append("*NSET,NSET=CLAMP")
    out += [",".join(map(str, clamp[i:i + 16])) for i in range(0, len(clamp), 16)]
    out.append(f"*NSET,NSET=TIPC\n{tipc}")
    # mid-thickness nodes on the top and bottom edges, for mode shapes (twist along s)
    edges = [nid[(i, j, (NK - 1) // 2)] for i in range(0, NI, 2) for j in (0, NJ - 1)]
    out.append("*NSET,NSET=EDGES")
    out += [",".join(map(str, edges[i:i + 16])) for i in range(0, len(edges), 16)]
    out.append("*MATERIAL,NAME=STEEL")
    out.append(material_cards(mat).rstrip())
    out.append(f"*DENSITY\n{RHO}")
    out.append("*SOLID SECTION,ELSET=SHEET,MATERIAL=STEEL")
    if clamp_kind == "full":
        out.append("*BOUNDARY\nCLAMP,1,3")
    else:
        # warping-free clamp: u_x = u_z = 0 and u_y = c * x * z, one free amplitude c
        # of the St-Venant warping of a thin rectangle (omega = x z); this frees
        # exactly the restraint that a beam clamp does not impose.
        out.append("*BOUNDARY\nCLAMP,1,1\nCLAMP,3,3")
        ref = nid[(0, NJ - 1, NK - 1)]
        xr, _, zr = nodes[ref]
        eqs, fix = [], []
        for n in clamp:
            x, _, z = nodes[n]
            if n == ref:
                continue
            if abs(x * z) < 1e-15:
                fix.append(n)
            else:
                eqs.append(f"*EQUATION\n2\n{n},2,1.0,{ref},2,{-(x * z) / (xr * zr):.12e}")
        out.append("*BOUNDARY")
        out += [f"{n},2,2" for n in fix]
        out += eqs
    for P in loads:
        out.append("*STEP,NLGEOM,INC=1000")
        out.append("*STATIC")
        out.append(f"{1.0 / incs},1.0,1e-6,{1.0 / incs}")
        out.append("*CLOAD")
        for n, f in w.items():
            out.append(f"{n},1,{P * f:.9e}")
        out.append("*NODE PRINT,NSET=TIPC\nU")
        if edges_out:
            out.append("*NODE PRINT,NSET=EDGES\nU")
        out.append("*END STEP")
        out.append("*STEP,PERTURBATION")
        out.append(f"*FREQUENCY\n{nmodes}")
        if edges_out:
            out.append("*NODE PRINT,NSET=EDGES\nU")
        out.append("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return len(nodes), len(elems)


def parse_dat(path, tip_set="TIPC"):
    """Displacements of node set `tip_set` in the static steps and, per
    frequency step, the frequencies and participation factors."""
    txt = open(path).read()
    blocks = re.split(r"(?=displacements \(vx,vy,vz\))|(?=E I G E N V A L U E   O U T P U T)|(?=P A R T I C I P A T I O N)", txt)
    tips, freqs, parts = [], [], []
    last_tip = None
    for bl in blocks:
        if bl.startswith("displacements") and f"for set {tip_set} " in bl.splitlines()[0]:
            line = [l for l in bl.splitlines()[1:] if l.strip()][0]
            v = line.split()
            last_tip = (float(v[1]), float(v[2]), float(v[3]))
        elif bl.startswith("E I G E N"):
            tips.append(last_tip)  # the static state this perturbation step is about
            fs = []
            for l in bl.splitlines():
                v = l.split()
                if len(v) == 5 and v[0].isdigit():
                    fs.append(float(v[3]))
            freqs.append(fs)
        elif bl.startswith("P A R T"):
            ps = []
            for l in bl.splitlines():
                v = l.split()
                if len(v) == 7 and v[0].isdigit():
                    ps.append([float(x) for x in v[1:]])
                if "E F F E C T" in l:
                    break
            parts.append(ps)
    return tips, freqs, parts


def run_solid(a):
    os.makedirs(a.out, exist_ok=True)
    job = os.path.join(a.out, "sheet")
    nn, ne = write_deck(job + ".inp", a.L, a.b, a.t, a.nl, a.nh, a.nt, a.mat, a.loads, a.modes, a.incs, a.clamp, a.edges)
    print(f"# deck {job}.inp: {nn} nodes, {ne} C3D20R elements", file=sys.stderr)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    if not a.reuse:
        r = subprocess.run(["nice", "-n", "10", "ccx", "-i", "sheet"], cwd=a.out, env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        open(job + ".log", "w").write(r.stdout)
        if "Job finished" not in r.stdout:
            raise SystemExit(f"ccx failed, see {job}.log")
    tips, freqs, parts = parse_dat(job + ".dat")
    case = f"solid,{a.mat},b/t={a.b / a.t:g},mesh={a.nl}x{a.nh}x{a.nt},clamp={a.clamp}"
    print("case,P,tip_x,tip_y,mode,f_Hz,kind")
    for P, tip, fs, ps in zip(a.loads, tips, freqs, parts):
        for m, (f, p) in enumerate(zip(fs, ps), 1):
            outp = abs(p[2]) + abs(p[3]) + abs(p[4])
            inp = abs(p[0]) + abs(p[1]) + abs(p[5])
            kind = "out" if outp > inp else "in"
            print(f"{case},{P:g},{tip[0]:.6e},{tip[1]:.6e},{m},{f:.6f},{kind}")


def beam_scene(a, dimension, P=1.0):
    nu = {"nu0": 0.3, "nu0g2": 0.0, "nu03": 0.3}[a.mat]
    spatial = dimension == "Spatial"
    up = ", up: Some([0.0, 0.0, 1.0])" if spatial else ""
    at = lambda x, y: f"[{x}, {y}, 0.0]" if spatial else f"[{x}, {y}]"
    force = f"[{P!r}, 0.0, 0.0]" if spatial else f"[{P!r}, 0.0]"
    # a planar beam bends with its section's `by` side in the plane
    sec = f"Rectangle(by: {a.b}, bz: {a.t})" if spatial else f"Rectangle(by: {a.t}, bz: {a.b})"
    return f"""(
    name: "sheet cantilever b={a.b} t={a.t}",
    dimension: {dimension},
    gravity: None,
    materials: {{ "steel": (e: {E}, nu: {nu}, rho: {RHO}) }},
    sections: {{ "sheet": {sec} }},
    nodes: [ (id: "A", at: {at(0.0, 0.0)}), (id: "B", at: {at(0.0, a.L)}) ],
    elements: [ (id: "sheet", type: Beam((nodes: ("A", "B"), material: "steel", section: "sheet"{up}, n: {a.n}))) ],
    fixed: [Node("A")],
    rigid: [],
    dofs: Deformations,
    loads: [ (node: "B", force: Some({force}), function: Some(Constant(1.0))) ],
    outputs: [Position("B")],
)
"""


def run_beam(a):
    os.makedirs(a.out, exist_ok=True)
    res = {}
    for dim in ("Spatial", "Planar"):
        scene = os.path.join(a.out, f"sheet_{dim.lower()}.ron")
        open(scene, "w").write(beam_scene(a, dim))
        rows = {}
        for P in a.loads:
            d = os.path.join(a.out, f"{dim.lower()}_P{P:g}")
            modes = a.modes if dim == "Spatial" else a.modes // 2
            if P == 0:
                cmd = [FLEXMB, "eig", scene, "--modes", str(modes)]
                r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                fs = parse_eig(r.stdout)
            else:
                # load sweep 0..P (continuation), last row is at P
                cmd = [FLEXMB, "sweep", scene, "--over", "load", "--from", "0", "--to", f"{P:g}",
                       "--n", str(a.sweep_n), "--modes", str(modes), "--out", d]
                r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                if r.returncode != 0:
                    raise SystemExit(r.stdout)
                lines = [l for l in open(os.path.join(d, "eigenfrequencies.csv")) if not l.startswith("#")]
                fs = [float(x) for x in lines[-1].strip().split(",")[1:]]
            tip = (0.0, a.L)
            if P != 0 and dim == "Spatial":
                sP = os.path.join(a.out, f"static_P{P:g}.ron")
                open(sP, "w").write(beam_scene(a, dim, P))
                r = subprocess.run([FLEXMB, "static", sP, "--steps", "20", "--out", d + "_static"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                if r.returncode != 0:
                    raise SystemExit(r.stdout)
                rowsB = [l for l in open(os.path.join(d + "_static", "node_positions.csv")) if not l.startswith("#")]
                xyz = rowsB[2].split(",")  # header, A, B
                tip = (float(xyz[0]), float(xyz[1]) - 0.0)
            rows[P] = (fs, tip)
        res[dim] = rows
    case = f"beam,{a.mat},b/t={a.b / a.t:g},n={a.n}"
    print("case,P,tip_x,tip_y,mode,f_Hz,kind")
    for P in a.loads:
        fs, tip = res["Spatial"][P]
        fin = list(res["Planar"][P][0])
        for m, f in enumerate(fs, 1):
            # in-plane if a planar frequency matches to 1e-4
            hit = [g for g in fin if abs(g - f) <= 1e-4 * f]
            kind = "in" if hit else "out"
            if hit:
                fin.remove(hit[0])
            print(f"{case},{P:g},{tip[0]:.6e},{tip[1] - a.L:.6e},{m},{f:.6f},{kind}")


def parse_eig(out):
    fs = []
    for l in out.splitlines():
        v = l.split()
        if len(v) >= 2 and v[0].isdigit():
            try:
                fs.append(float(v[1]))
            except ValueError:
                pass
    return fs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=["solid", "beam", "deck"])
    ap.add_argument("--L", type=float, default=0.2)
    ap.add_argument("--b", type=float, default=0.03)
    ap.add_argument("--t", type=float, default=0.001)
    ap.add_argument("--nl", type=int, default=50)
    ap.add_argument("--nh", type=int, default=8)
    ap.add_argument("--nt", type=int, default=2)
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--mat", default="nu0")
    ap.add_argument("--loads", type=lambda s: [float(x) for x in s.split(",")], default=[0.0])
    ap.add_argument("--modes", type=int, default=12)
    ap.add_argument("--incs", type=int, default=10)
    ap.add_argument("--sweep-n", type=int, default=11)
    ap.add_argument("--out", default="/tmp/sheet22")
    ap.add_argument("--edges", action="store_true", help="also print U of the edge nodes (static state and modes) to sheet.dat, for twist.py")
    ap.add_argument("--reuse", action="store_true", help="parse an existing sheet.dat in --out, do not run ccx")
    ap.add_argument("--clamp", choices=["full", "warpfree"], default="full",
                    help="solid clamp: all nodes fixed, or warping (u_y = c x z) left free")
    a = ap.parse_args()
    # --loads are alpha = P L^2 / (E I_weak); P follows from the section
    a.alpha = a.loads
    a.loads = [al * E * a.b * a.t ** 3 / 12.0 / a.L ** 2 for al in a.alpha]
    if a.what == "solid":
        run_solid(a)
    elif a.what == "beam":
        run_beam(a)
    else:
        os.makedirs(a.out, exist_ok=True)
        print(write_deck(os.path.join(a.out, "sheet.inp"), a.L, a.b, a.t, a.nl, a.nh, a.nt, a.mat, a.loads, a.modes, a.incs, a.clamp))


if __name__ == "__main__":
    main()
