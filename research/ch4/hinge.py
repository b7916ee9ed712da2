#!/usr/bin/env python3
"""One base cross-hinge of thesis Table 4.3 as a CalculiX C3D20R solid: the
independent check of issue 17 (`xtask/src/ch4/hinge_check.rs`, docs/reproduce.md,
"Chapter 4: one base cross-hinge against CalculiX").

Geometry: exactly the hinge `hb_x1` of the mechanism's scene (xtask/src/ch4/
scene.rs `add_hinge`, layout.rs): rotation axis along z through the origin,
the hinge's line along y. Five steel sheets, each L = 50 mm long and
t = 0.5 mm thick, stacked in z with 1 mm gaps (outer, cross, main, cross,
outer; heights 10, 15, 33, 15, 10 mm, centred at z = 38.5, 25, 0, -25,
-38.5 mm), the main and outer sheets along d1 = (-1, 1, 0)/sqrt2, the cross
sheets along d2 = (1, 1, 0)/sqrt2, each centred on the axis (they cross on
it). The sheets' end faces at y = -17.68 mm (side A) are clamped; their end
faces at y = +17.68 mm (side B) move with a rigid body that carries a
0.15 kg point mass at (0, 0.15, -0.05) m (the flexmb model's massless
L-shaped link from B).

The rigid body is a block of stiff, nearly massless C3D20R elements
(E = 10 x steel, rho = 1e-3 kg/m^3; 44 x 158 x 105 mm, enclosing the sheets'
B ends and the mass point) into which the B end-face nodes and the mass node
are embedded by linear *EQUATIONs u = sum N_i(xi) u_i over the 20 nodes of
the block element that contains them. That is exact under any large motion
(x = X + u, and X = sum N_i X_i), and the block's own compliance is far out
of the way (it changes f2 by about 1e-5). It replaces *RIGID BODY, under
which Newton diverged here, under a moment on the rotation node (also in
0.3 deg increments) and under a prescribed rotation alike: the rigid body's
linearized constraints strain the axially stiff sheets at every iteration
(residuals of 1e2-1e7 N at B that grow from one iteration to the next); a
single sheet (research/ch3/flexure.py) converges with it, slowly.

Material (--mat): `nu0`, E = 2.1e11 Pa, G = 8e10 Pa with all Poisson ratios
zero (*ELASTIC,TYPE=ENGINEERING CONSTANTS): the flexmb beams' E and G, and no
Poisson coupling, which beam theory lacks, so that every difference is
kinematic. That material is not isotropic (isotropy with nu = 0 needs
G = E/2): its axes are each sheet's own (*ORIENTATION: 1 along the sheet's
length, 2 along z, 3 through the thickness), as a beam's E and G are; in the
global axes a sheet at 45 deg would be 13.5 % softer in bending
(1/E_45 = 1/2E + 1/4G). `nu`, isotropic steel with nu = E/2G - 1 = 0.3125
(the same E and G). rho = 7800 kg/m^3.

Per moment M, one deck: an NLGEOM *STATIC step from 0 to a couple of dead
forces (+-F along y at (+-22, 60, 0) mm of the block, F = M / 44 mm) in
increments of at most about 1.25 deg, printing at each the displacements of those two nodes
(the rotation phi of the line between them and the couple's moment about z,
M cos phi) and of B = (0, 17.68, 0) mm (a node embedded in the block), then
a *FREQUENCY perturbation step about that prestressed state. One deck per
moment, because in CalculiX 2.20 a static step after a perturbation step
diverges (research/ch3/flexure.py).

Usage (from the repository root):
  python3 research/ch4/hinge.py --ms 0.3225,0.645,0.9675,1.29 --mesh 25,16,8,5,2 --out /tmp/ch4/hinge --csv STEM
  (the moments listed, in N m, their negatives, and 0)
Writes two CSV files: STEM.csv with
  case,M,phi_deg,ux,uy,mode,f_Hz
(one row per mode of each deck; M the couple's moment about z in the deformed
state in N m, phi the rotation of B about z, ux, uy B's displacement in m)
and STEM_curve.csv with
  case,M,phi_deg,ux,uy
(every increment of every deck), each with '#' lines saying how it was made.
"""
import argparse, math, os, subprocess, sys, time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../sheet22"))
from sheet import mesh

L, T, GAP = 0.05, 0.5e-3, 1e-3
E, G, RHO = 2.1e11, 8.0e10, 7800.0
HEIGHTS = {"main": 33e-3, "cross": 15e-3, "outer": 10e-3}
S2 = math.sqrt(0.5)
D1, D2 = (-S2, S2, 0.0), (S2, S2, 0.0)
MASS, MASS_AT = 0.15, (0.0, 0.15, -0.05)
C = 0.5 * L * S2
B_NODE = (0.0, C, 0.0)
# the block: grid lines in x, y, z (m); the couple acts at (+-X_F, Y_F, 0)
BLOCK_X = [-0.022 + 0.0055 * i for i in range(9)]
BLOCK_Y = [C - 0.002, C + 0.004, 0.03, 0.06, 0.09, 0.12, 0.16]
BLOCK_Z = [-0.06 + 0.015 * i for i in range(8)]
X_F, Y_F = 0.022, 0.06
BLOCK_E, BLOCK_RHO = 10 * E, 1e-3


def sheets():
    """(tag, direction, z of mid-height, height) as scene.rs five_sheets."""
    m, c, o = HEIGHTS["main"], HEIGHTS["cross"], HEIGHTS["outer"]
    zc = 0.5 * m + GAP + 0.5 * c
    zo = 0.5 * m + GAP + c + GAP + 0.5 * o
    return [("main", D1, 0.0, m), ("cross_up", D2, zc, c), ("cross_down", D2, -zc, c),
            ("outer_up", D1, zo, o), ("outer_down", D1, -zo, o)]


def material_cards(mat):
    if mat == "nu0":
        return ("*ELASTIC,TYPE=ENGINEERING CONSTANTS\n"
                f"{E:.6e},{E:.6e},{E:.6e},0.,0.,0.,{G:.6e},{G:.6e}\n{G:.6e}")
    if mat == "nu":
        return f"*ELASTIC\n{E:.6e},{E / (2 * G) - 1:.6f}"
    if mat == "iso0":
        return f"*ELASTIC\n{E:.6e},0.0"
    raise SystemExit(f"unknown material {mat}")


def sheet_model(a):
    """Nodes {id: xyz}, elements [(id, 20 ids, direction)], the clamp and
    B-end node lists."""
    nodes, elems, clamp, bend = {}, [], [], []
    on = oe = 0
    nl, nmain, ncross, nouter, nt = a.mesh
    nh = {"main": nmain, "cross": ncross, "outer": nouter}
    for tag, d, zc, h in sheets():
        sn, se, nid, (NI, NJ, NK) = mesh(L, h, T, nl, nh[tag.split("_")[0]], nt)
        # sheet.mesh: thickness along x, length along y (0..L), height along z;
        # (x, y, z) -> x nu + (y - L/2) d + (z + zc) e_z with nu = d x e_z, a
        # proper rotation (det [nu, d, e_z] = 1), so the elements stay right-handed
        nu = (d[1], -d[0], 0.0)
        for n, (x, y, z) in sn.items():
            s = y - 0.5 * L
            nodes[on + n] = (x * nu[0] + s * d[0], x * nu[1] + s * d[1], z + zc)
        elems += [(oe + e, [on + k for k in ns], d) for e, ns in se]
        clamp += [on + n for (i, j, k), n in nid.items() if i == 0]
        bend += [on + n for (i, j, k), n in nid.items() if i == NI - 1]
        on += max(sn)
        oe += len(se)
    return nodes, elems, clamp, bend


def block(first_node, first_elem):
    """The stiff block on the grid BLOCK_X x BLOCK_Y x BLOCK_Z: nodes {id: xyz},
    elements [(id, 20 ids, (i, j, k) of the cell)] and the grid's node ids."""
    NI, NJ, NK = 2 * len(BLOCK_X) - 1, 2 * len(BLOCK_Y) - 1, 2 * len(BLOCK_Z) - 1
    mid = lambda g, i: g[i // 2] if i % 2 == 0 else 0.5 * (g[i // 2] + g[i // 2 + 1])
    nid, nodes, c = {}, {}, first_node - 1
    for i in range(NI):
        for j in range(NJ):
            for k in range(NK):
                if (i % 2) + (j % 2) + (k % 2) <= 1:
                    c += 1
                    nid[(i, j, k)] = c
                    nodes[c] = (mid(BLOCK_X, i), mid(BLOCK_Y, j), mid(BLOCK_Z, k))
    elems, e = [], first_elem - 1
    for ei in range(len(BLOCK_X) - 1):
        for ej in range(len(BLOCK_Y) - 1):
            for ek in range(len(BLOCK_Z) - 1):
                i0, j0, k0 = 2 * ei, 2 * ej, 2 * ek
                P = lambda a, b, cc: nid[(i0 + a, j0 + b, k0 + cc)]
                corners = [P(0, 0, 0), P(2, 0, 0), P(2, 2, 0), P(0, 2, 0), P(0, 0, 2), P(2, 0, 2), P(2, 2, 2), P(0, 2, 2)]
                mids = [P(1, 0, 0), P(2, 1, 0), P(1, 2, 0), P(0, 1, 0), P(1, 0, 2), P(2, 1, 2), P(1, 2, 2), P(0, 1, 2),
                        P(0, 0, 1), P(2, 0, 1), P(2, 2, 1), P(0, 2, 1)]
                e += 1
                elems.append((e, corners + mids, (ei, ej, ek)))
    return nodes, elems, nid


def shape20(r, s, t):
    """C3D20 serendipity shape functions at (r, s, t) in [-1, 1]^3, in the
    node order of `block` (corners, then the mid-side nodes)."""
    cs = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
    n = [0.125 * (1 + r * a) * (1 + s * b) * (1 + t * c) * (r * a + s * b + t * c - 2) for a, b, c in cs]
    ms = [(0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1), (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
          (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    for a, b, c in ms:
        if a == 0:
            n.append(0.25 * (1 - r * r) * (1 + s * b) * (1 + t * c))
        elif b == 0:
            n.append(0.25 * (1 + r * a) * (1 - s * s) * (1 + t * c))
        else:
            n.append(0.25 * (1 + r * a) * (1 + s * b) * (1 - t * t))
    return n


def embed(p, elems):
    """(20 node ids, weights) of the block element containing point p: its
    cells are boxes with mid-side nodes at the midpoints, so the local
    coordinates are affine in p."""
    def cell(g, x):
        for i in range(len(g) - 1):
            if g[i] - 1e-12 <= x <= g[i + 1] + 1e-12:
                return i, 2 * (x - g[i]) / (g[i + 1] - g[i]) - 1
        raise SystemExit(f"point {p} outside the block")
    (i, r), (j, s), (k, t) = cell(BLOCK_X, p[0]), cell(BLOCK_Y, p[1]), cell(BLOCK_Z, p[2])
    ns = next(ns for _, ns, c in elems if c == (i, j, k))
    return ns, shape20(r, s, t)


def equations(node, ns, w):
    """*EQUATION cards u_node - sum w_i u_i = 0 for the three directions."""
    terms = [(node, 1.0)] + [(n, -x) for n, x in zip(ns, w) if abs(x) > 1e-14]
    out = []
    for dof in (1, 2, 3):
        out.append(f"*EQUATION\n{len(terms)}")
        cells = [f"{n},{dof},{c:.12e}" for n, c in terms]
        out += [",".join(cells[i:i + 4]) for i in range(0, len(cells), 4)]
    return out


def write(path, a, m, incs):
    nodes, elems, clamp, bend = sheet_model(a)
    top = max(nodes)
    bnodes, belems, bnid = block(top + 1, len(elems) + 1)
    top = max(bnodes)
    e_node, b_node = top + 1, top + 2
    ni, nj = len(BLOCK_X) * 2 - 2, BLOCK_Y.index(Y_F) * 2
    nk = BLOCK_Z.index(min(BLOCK_Z, key=abs)) * 2
    f_plus, f_minus = bnid[(ni, nj, nk)], bnid[(0, nj, nk)]
    assert abs(bnodes[f_plus][0] - X_F) < 1e-12 and abs(bnodes[f_minus][0] + X_F) < 1e-12
    assert abs(bnodes[f_plus][1] - Y_F) < 1e-12 and abs(bnodes[f_plus][2]) < 1e-12
    out = ["*HEADING", f"base cross-hinge C3D20R mesh {a.mesh} mat={a.mat} M={m}", "*NODE"]
    out += [f"{n},{x:.12e},{y:.12e},{z:.12e}" for n, (x, y, z) in list(nodes.items()) + list(bnodes.items())]
    out.append(f"{e_node},{MASS_AT[0]:.12e},{MASS_AT[1]:.12e},{MASS_AT[2]:.12e}")
    out.append(f"{b_node},{B_NODE[0]:.12e},{B_NODE[1]:.12e},{B_NODE[2]:.12e}")
    for k, d in enumerate((D1, D2), 1):
        out.append(f"*ELEMENT,TYPE=C3D20R,ELSET=SHEETS{k}")
        for e, ns, dd in elems:
            if dd == d:
                out.append(f"{e}," + ",".join(map(str, ns[:15])) + ",")
                out.append(",".join(map(str, ns[15:])))
    out.append("*ELEMENT,TYPE=C3D20R,ELSET=BLOCK")
    for e, ns, _ in belems:
        out.append(f"{e}," + ",".join(map(str, ns[:15])) + ",")
        out.append(",".join(map(str, ns[15:])))
    out.append(f"*ELEMENT,TYPE=MASS,ELSET=EMASS\n{belems[-1][0] + 1},{e_node}")
    out.append("*NSET,NSET=CLAMP")
    out += [",".join(map(str, clamp[i:i + 16])) for i in range(0, len(clamp), 16)]
    out.append(f"*NSET,NSET=COUPLE\n{f_plus},{f_minus}\n*NSET,NSET=BN\n{b_node}")
    out.append(f"*MATERIAL,NAME=STEEL\n{material_cards(a.mat)}\n*DENSITY\n{RHO}")
    out.append(f"*MATERIAL,NAME=STIFF\n*ELASTIC\n{BLOCK_E:.6e},0.3\n*DENSITY\n{BLOCK_RHO}")
    for k, d in enumerate((D1, D2), 1):
        # material axes: 1 along the sheet, 2 along z, 3 through the thickness
        out.append(f"*ORIENTATION,NAME=OR{k},SYSTEM=RECTANGULAR\n{d[0]:.12f},{d[1]:.12f},{d[2]:.12f},0.,0.,1.")
        out.append(f"*SOLID SECTION,ELSET=SHEETS{k},MATERIAL=STEEL,ORIENTATION=OR{k}")
    out.append("*SOLID SECTION,ELSET=BLOCK,MATERIAL=STIFF")
    out.append(f"*MASS,ELSET=EMASS\n{MASS}")
    for n in bend:
        out += equations(n, *embed(nodes[n], belems))
    out += equations(e_node, *embed(MASS_AT, belems))
    out += equations(b_node, *embed(B_NODE, belems))
    out.append("*BOUNDARY\nCLAMP,1,3")
    f = m / (2 * X_F)
    # increments of 1/incs, cut where Newton fails (ccx's divergence check
    # stopped fixed increments near convergence at 11-14 deg)
    out.append("*STEP,NLGEOM,INC=1000")
    if a.rtol is not None:
        out.append(f"*CONTROLS,PARAMETERS=FIELD\n{a.rtol:.3e},{a.rtol:.3e}")
    out.append("*STATIC")
    out.append(f"{1.0 / incs:.8e},1.0,{1e-4 / incs:.8e},{1.0 / incs:.8e}")
    out.append(f"*CLOAD\n{f_plus},2,{f:.12e}\n{f_minus},2,{-f:.12e}")
    out.append("*NODE PRINT,NSET=COUPLE\nU\n*NODE PRINT,NSET=BN\nU\n*END STEP")
    out.append(f"*STEP,PERTURBATION\n*FREQUENCY\n{a.modes}\n*END STEP")
    open(path, "w").write("\n".join(out) + "\n")
    return len(nodes), len(elems), (f_plus, f_minus, b_node)


def parse(path, probes):
    """Per increment (time, displacements of the probe nodes) of the static
    step, and the frequencies of the perturbation step."""
    lines = open(path).read().splitlines()
    incs, freqs, cur = [], None, {}
    i = 0
    while i < len(lines):
        l = lines[i].strip()
        w = l.split()
        if freqs is None and l.startswith("displacements (vx,vy,vz) for set"):
            t = float(w[-1])
            j = i + 1
            while j < len(lines) and (not lines[j].strip() or lines[j].split()[0].isdigit()):
                v = lines[j].split()
                if v:
                    cur[int(v[0])] = (t, [float(x) for x in v[1:4]])
                j += 1
            if all(p in cur and cur[p][0] == t for p in probes):
                incs.append((t, [cur[p][1] for p in probes]))
                cur = {}
            i = j
            continue
        elif "E I G E N V A L U E   O U T P U T" in l:
            fs = []
            j = i + 1
            while j < len(lines) and "P A R T I C I P" not in lines[j]:
                v = lines[j].split()
                if len(v) == 5 and v[0].isdigit():
                    fs.append(float(v[3]))
                j += 1
            freqs = fs
            i = j
            continue
        i += 1
    return incs, freqs or []


def state(t, u, m):
    """(M, phi, ux, uy) from the probes' displacements at load fraction t:
    phi of the line between the couple's nodes, the couple's moment about z
    in the deformed state, B's displacement."""
    (up, um, ub) = u
    dx = 2 * X_F + up[0] - um[0]
    dy = up[1] - um[1]
    phi = math.atan2(dy, dx)
    # forces +-F along y at the deformed nodes: M = F (x+ - x-)
    f = t * m / (2 * X_F)
    return f * dx, phi, ub[0], ub[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ms", type=lambda s: [float(x) for x in s.split(",")], default=[0.3225, 0.645, 0.9675, 1.29],
                    help="moments of the couple at rest (N m); their negatives and 0 are run too")
    ap.add_argument("--mesh", type=lambda s: [int(x) for x in s.split(",")], default=[25, 16, 8, 5, 2],
                    help="elements along the length, the heights of the main, cross and outer sheets, and the thickness")
    ap.add_argument("--mat", choices=["nu0", "nu", "iso0"], default="nu0")
    ap.add_argument("--modes", type=int, default=8)
    ap.add_argument("--inc", type=float, default=0.081,
                    help="the largest load increment (N m; 0.081 N m turns the hinge by about 1.25 deg)")
    ap.add_argument("--only", type=lambda s: [float(x) for x in s.split(",")],
                    help="run only these signed moments of the set: a share of the work for one process"
                         " (then --reuse without --only in one directory with all the .dat files lists them all)")
    ap.add_argument("--sides", choices=["both", "pos", "neg"], default="both",
                    help="the signs of the moments (each with M = 0)")
    ap.add_argument("--rtol", type=float, help="ccx's residual and correction criteria R_n, C_n (default 0.005, 0.01)")
    ap.add_argument("--out", default="/tmp/ch4/hinge")
    ap.add_argument("--csv", required=True, help="output stem: STEM.csv and STEM_curve.csv")
    ap.add_argument("--reuse", action="store_true", help="parse existing .dat files in --out, do not run ccx")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    pos, neg = a.sides != "neg", a.sides != "pos"
    moments = sorted(([-x for x in a.ms] if neg else []) + [0.0] + (a.ms if pos else []))
    mesh_tag = "x".join(map(str, a.mesh))
    case = f"solid,{a.mat},mesh={mesh_tag}"
    rows, curve, log = [], [], []
    for m in moments:
        job = f"m{m:+.4f}".replace("+", "p").replace("-", "n").replace(".", "_")
        incs = max(1, math.ceil(abs(m) / a.inc - 1e-9))
        nn, ne, probes = write(os.path.join(a.out, job + ".inp"), a, m, incs)
        t0 = time.time()
        if a.only is not None and m not in a.only:
            continue
        run = not a.reuse
        if run:
            env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
            r = subprocess.run(["nice", "-n", "10", "ccx", "-i", job], cwd=a.out, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            open(os.path.join(a.out, job + ".log"), "w").write(r.stdout)
            if "Job finished" not in r.stdout:
                raise SystemExit(f"ccx failed, see {a.out}/{job}.log")
        dt = time.time() - t0
        if not run:
            # ccx's own count of the run's time, from its saved output
            for l in open(os.path.join(a.out, job + ".log")).read().splitlines():
                if "Total CalculiX Time" in l:
                    dt = float(l.split(":")[1])
        incs_out, freqs = parse(os.path.join(a.out, job + ".dat"), probes)
        if not freqs or not incs_out:
            raise SystemExit(f"{job}: no frequencies or no increments in the .dat file")
        t, u = incs_out[-1]
        if abs(t - 1.0) > 1e-9:
            raise SystemExit(f"{job}: the static step ended at time {t}")
        mm, phi, ux, uy = state(t, u, m)
        msg = (f"{job}: {nn} sheet nodes, {ne} sheet elements, {incs} increments, phi = {math.degrees(phi):.4f} deg,"
               f" ccx {dt:.0f} s{'' if run else ' (parsed)'}")
        print("# " + msg, file=sys.stderr)
        log.append(msg)
        for k, f in enumerate(freqs, 1):
            rows.append(f"{case},{mm:.9e},{math.degrees(phi):.9f},{ux:.9e},{uy:.9e},{k},{f:.6f}")
        for (t, u) in incs_out:
            mm, phi, ux, uy = state(t, u, m)
            curve.append(f"{case},{mm:.9e},{math.degrees(phi):.9f},{ux:.9e},{uy:.9e}")
    head = [f"# python3 research/ch4/hinge.py {' '.join(sys.argv[1:])}",
            "# CalculiX 2.20 C3D20R, one base cross-hinge of thesis Table 4.3 (L = 50 mm, t = 0.5 mm, heights 33/15/10 mm),"
            f" mesh {mesh_tag} (along the length; main, cross, outer heights; thickness), mat={a.mat}"
            " (nu0: E = 2.1e11, G = 8e10, all nu = 0, in each sheet's axes; nu: isotropic nu = 0.3125), rho = 7800;"
            f" side A clamped, side B's end faces and a {MASS} kg point mass at {MASS_AT} m embedded in a stiff massless block;"
            " per moment one deck: NLGEOM *STATIC under a couple of dead forces from 0 to M in increments, then"
            " *FREQUENCY (perturbation step); M the couple's moment about z and phi B's rotation, both in the deformed state"]
    head += [f"# {l}" for l in log]
    with open(a.csv + ".csv", "w") as fh:
        fh.write("\n".join(head + ["case,M,phi_deg,ux,uy,mode,f_Hz"] + rows) + "\n")
    with open(a.csv + "_curve.csv", "w") as fh:
        fh.write("\n".join(head + ["case,M,phi_deg,ux,uy"] + curve) + "\n")


if __name__ == "__main__":
    main()
