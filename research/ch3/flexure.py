#!/usr/bin/env python3
"""The short sheet flexure of thesis §3.5.1 (Fig. 3.9) as a CalculiX C3D20R
solid: the FE reference of `cargo xtask reproduce ch3` (issue 16).

Layout as xtask/src/ch3.rs: the flexure along x from the origin (l = 0.04 m),
its height along y (h = 0.04 m, centred), its thickness along z (t = 0.3 mm,
centred); steel E = 2.1e11 Pa, nu = 0.3125 (G = 8e10 Pa), rho = 7800 kg/m^3.
The end x = 0 is clamped. The end face x = l and the mass node E at
(0.29, 0, -0.1) form one *RIGID BODY (the thesis's massless L-shaped link and
its 0.01 kg point mass) whose reference node is the end's centre (l, 0, 0).
Per moment, one deck: an NLGEOM *STATIC step from 0 to M about y on the rigid
body's rotation node, then a *FREQUENCY perturbation step about that
prestressed state. (One deck per moment: in CalculiX 2.20 a static step with
a moment on the rotation node that follows a perturbation step diverges, also
without the mass node; the same static steps without the perturbation steps
between them converge.)

`--offset E` moves the mass node to (0.29, E, -0.1): the link's tip lifted by
E along the sheet's height, out of the mirror plane y = 0 of the flexure (the
asymmetric variant of docs/reproduce.md, "Where modes 4 and 5 meet"; E = 0.02
is the link attached at the sheet's top edge). With no gravity and a massless
link the static states are those of E = 0; only the inertia moves.

Usage: python3 flexure.py --ms 0.1,0.2,0.3,0.4 --nl 20 --nh 20 --nt 2 --out DIR
       [--offset E] [--sides neg --refine LEVELS]
(the moments listed and their negatives, and M = 0)
Prints CSV: case,M,phi_deg,mode,f_Hz (phi: the rotation node's U2, in degrees)
"""
import argparse, math, os, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../sheet22"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sheet import mesh
import deck

L, H, T = 0.04, 0.04, 3e-4
E, NU, RHO = 2.1e11, 0.3125, 7800.0
MASS_AT = (0.29, 0.0, -0.1)


def mass_at(a):
    return (MASS_AT[0], MASS_AT[1] + a.offset, MASS_AT[2])


def write(path, a, m):
    # sheet.mesh: length along its y, height along z, thickness along x;
    # (x, y, z) -> (y, z, x) is a cyclic permutation (a proper rotation)
    nodes, elems, nid, (NI, NJ, NK) = mesh(L, H, T, a.nl, a.nh, a.nt)
    out = ["*HEADING", f"short sheet flexure C3D20R {a.nl}x{a.nh}x{a.nt} mass offset {a.offset}", "*NODE"]
    for n, (x, y, z) in nodes.items():
        out.append(f"{n},{y:.9e},{z:.9e},{x:.9e}")
    top = max(nodes)
    e_node, ref, rot = top + 1, top + 2, top + 3
    at = mass_at(a)
    out.append(f"{e_node},{at[0]:.9e},{at[1]:.9e},{at[2]:.9e}")
    out.append(f"{ref},{L:.9e},0.0,0.0\n{rot},{L:.9e},0.0,0.0")
    out.append("*ELEMENT,TYPE=C3D20R,ELSET=FLEX")
    for e, ns in elems:
        out.append(f"{e}," + ",".join(map(str, ns[:15])) + ",")
        out.append(",".join(map(str, ns[15:])))
    out.append(f"*ELEMENT,TYPE=MASS,ELSET=EMASS\n{max(e for e, _ in elems) + 1},{e_node}")
    clamp = [n for (i, j, k), n in nid.items() if i == 0]
    tips = [n for (i, j, k), n in nid.items() if i == NI - 1]
    for name, ns in (("CLAMP", clamp), ("RIG", tips + [e_node])):
        out.append(f"*NSET,NSET={name}")
        out += [",".join(map(str, ns[i:i + 16])) for i in range(0, len(ns), 16)]
    out.append(f"*NSET,NSET=ROTN\n{rot}")
    out.append(f"*MATERIAL,NAME=STEEL\n*ELASTIC\n{E:.6e},{NU}\n*DENSITY\n{RHO}")
    out.append("*SOLID SECTION,ELSET=FLEX,MATERIAL=STEEL")
    out.append("*MASS,ELSET=EMASS\n0.01")
    out.append(f"*RIGID BODY,NSET=RIG,REF NODE={ref},ROT NODE={rot}")
    out.append("*BOUNDARY\nCLAMP,1,3")
    # a.incs increments per 0.1 N m
    incs = max(1, math.ceil(a.incs * abs(m) / 0.1))
    out.append("*STEP,NLGEOM,INC=1000\n*STATIC")
    out.append(f"{1.0 / incs},1.0,1e-6,{1.0 / incs}")
    out.append(f"*CLOAD\n{rot},2,{m:.9e}")
    out.append("*NODE PRINT,NSET=ROTN\nU\n*END STEP")
    out.append(f"*STEP,PERTURBATION\n*FREQUENCY\n{a.modes}\n*END STEP")
    open(path, "w").write("\n".join(out) + "\n")
    return len(nodes), len(elems)


def parse(path):
    """Rotation-node U2 of each static step (its last increment before the
    step's eigenvalue output) and the frequencies of each perturbation step,
    in order."""
    rots = []
    last = None
    lines = open(path).read().splitlines()
    for i, l in enumerate(lines):
        if l.strip().startswith("displacements (vx,vy,vz) for set ROTN"):
            v = [s for s in lines[i + 1:i + 4] if s.strip()][0].split()
            last = float(v[2])
        elif "E I G E N V A L U E   O U T P U T" in l:
            rots.append(last)
    return rots, deck.parse_frequencies(path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ms", type=lambda s: [float(x) for x in s.split(",")], default=[0.1, 0.2, 0.3, 0.4])
    ap.add_argument("--nl", type=int, default=20)
    ap.add_argument("--nh", type=int, default=20)
    ap.add_argument("--nt", type=int, default=2)
    ap.add_argument("--modes", type=int, default=6)
    ap.add_argument("--incs", type=int, default=4)
    ap.add_argument("--offset", type=float, default=0.0,
                    help="the mass node's y (m): 0 is the mirror-symmetric layout")
    ap.add_argument("--out", default="/tmp/ch3/flexure")
    ap.add_argument("--sides", choices=["both", "pos", "neg"], default="both",
                    help="the moments' signs to run (pos and neg both include M = 0)")
    ap.add_argument("--reuse", action="store_true", help="parse existing .dat files in --out, do not run ccx")
    ap.add_argument("--refine", type=int, default=0, metavar="LEVELS",
                    help="then LEVELS times: --per-level moments over the two intervals around "
                         "the one where f5 - f4 is smallest so far")
    ap.add_argument("--per-level", type=int, default=9,
                    help="moments per refinement level (odd; 9: the step shrinks by 4, 5: by 2)")
    ap.add_argument("--resume", action="store_true",
                    help="run ccx only for decks in --out without a finished log")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    print("case,M,phi_deg,mode,f_Hz")
    moments = sorted(([-m for m in a.ms] if a.sides != "pos" else []) + [0.0] + (a.ms if a.sides != "neg" else []))
    done = {m: run(a, m) for m in moments}
    for _ in range(a.refine):
        grid = sorted(m for m in done if m != 0.0)  # the search leaves out the deck at rest
        i = min(range(len(grid)), key=lambda k: gap(done[grid[k]]))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        n = a.per_level - 1
        for k in range(n + 1):
            m = round(lo + (hi - lo) * k / n, 10)
            if m not in done:
                done[m] = run(a, m)
    best = min(done, key=lambda m: gap(done[m]))
    print(f"# closest: M = {best:g}, f5 - f4 = {gap(done[best]):.6f} Hz", file=sys.stderr)


def gap(point):
    """f5 - f4 of a run's (phi, freqs)."""
    return point[1][4] - point[1][3]


def run(a, m):
    """One deck at moment m: writes, runs (unless --reuse) and parses it,
    prints its CSV rows and returns (phi in degrees, frequencies)."""
    digits = 3 if round(m, 3) == m else 7
    job = f"m{m:+.{digits}f}".replace("+", "p").replace("-", "n").replace(".", "_")
    nn, ne = write(os.path.join(a.out, job + ".inp"), a, m if m != 0.0 else 1e-12)
    print(f"# {job}: {nn} nodes, {ne} elements", file=sys.stderr)
    log = os.path.join(a.out, job + ".log")
    finished = os.path.exists(log) and "Job finished" in open(log).read()
    if not (a.reuse or (a.resume and finished)):
        deck.run_ccx(job, a.out)
    rots, freqs = parse(os.path.join(a.out, job + ".dat"))
    if len(rots) != 1:
        raise SystemExit(f"{job}: {len(rots)} perturbation steps parsed, 1 expected")
    phi = math.degrees(rots[0])
    case = f"mesh={a.nl}x{a.nh}x{a.nt}" + (f" offset={a.offset:g}" if a.offset else "")
    for k, f in enumerate(freqs[0], 1):
        print(f"solid,{case},{m:g},{phi:.6f},{k},{f:.6f}", flush=True)
    return phi, freqs[0]


if __name__ == "__main__":
    main()
