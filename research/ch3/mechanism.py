#!/usr/bin/env python3
"""The small compliant mechanism of thesis §3.5.3 (Fig. 3.13, Table 3.2) as
a CalculiX solid: the FE reference (the thesis's "FE-Ansys") of Fig. 3.14 and
Table 3.3 in `cargo xtask reproduce ch3` (issue 16).

Nodes of Table 3.2: 1 (0.02, 0.02, -0.02), 2 (0.02, -0.02, -0.02),
3 (0, 0, 0.02), 4 (0.04, 0, 0.02), 5 (0.04, 0, 0), 6 (0.29, 0, 0),
7 (0.29, -0.1, 0). Parts:
* flexure A from node 1 to node 2: the §3.5.1 sheet (l = h = 40 mm,
  t = 0.3 mm, steel E = 2.1e11, nu = 0.3125, rho = 7800), along -y at
  x = 0.02, its height along z (z from -0.04 to 0), its thickness along x;
* flexure B from node 3 to node 4: the same sheet along +x at y = 0, its
  height along z (0 to 0.04), its thickness along y;
  both C3D20R, nl x nh x nt elements (length, height, thickness) as
  research/ch3/flexure.py;
* the component of §3.5.2 from node 5 to node 6 (research/ch3/component.py,
  C3D20 on flexmb's mesh);
* the rigid beams 2-5 and 4-5 of the thesis: flexure A's face at node 2,
  flexure B's face at node 4 and the component's face at node 5 form one
  *RIGID BODY with its reference node at node 5; the rigid beam 6-7 and the
  0.01 kg mass: the component's face at node 6 and the mass node 7 form
  another. The faces at nodes 1 and 3 are clamped.

One deck per rotation phi (degrees) of node 5 about z: an NLGEOM static
step that turns node 5's rigid body to phi (a boundary condition on its
rotation node; with `--gravity` also 9.81 m/s^2 along -z, on the solid by
*DLOAD GRAV and on the mass node by a *CLOAD of -m g), then a *FREQUENCY
perturbation step about that prestressed state with the rotation released
(*BOUNDARY, OP=NEW keeps only the clamps). Rotation control converges in a
few increments where moment control (a *CLOAD on the rotation node) needed
64 increments for 0.1 N m on the 8 x 8 x 1 flexure mesh; at the same state
both give the same frequencies to 7 digits (phi = 5.51 deg, checked), so
the frequencies are those of the moment-loaded mechanism. The reaction on
the rotation node is the moment M that holds phi. Without gravity these are
the points of Fig. 3.14; with gravity, node 7's z-displacement is Table 3.3.

Usage: python3 mechanism.py --phis 0,5,-5,10 [--gravity] [--nl 20 --nh 20 --nt 2] [--h 0.005] --out DIR
Prints CSV: case,gravity,phi_set,M,phi_deg,z7,mode,f_Hz
(M = the reaction moment about z on the rotation node (N m), phi_deg its
rotation U3 in degrees, z7 = node 7's U3 (m))
"""
import argparse, math, os, sys, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import deck
import component

L, H, T = 0.04, 0.04, 3e-4
E, NU, RHO = 2.1e11, 0.3125, 7800.0
G = 9.81


def write(path, a, value, gravity):
    out = ["*HEADING", f"thesis 3.5.3 mechanism, flexures {a.nl}x{a.nh}x{a.nt}, component h = {a.h}, phi = {value} deg" + (", gravity" if gravity else "")]
    hA = (T / a.nt, L / a.nl, H / a.nh)
    nA, eA = deck.boxes([((0.02 - T / 2, -0.02, -0.04), (0.02 + T / 2, 0.02, 0.0), "A")], hA)
    hB = (L / a.nl, T / a.nt, H / a.nh)
    nB, eB = deck.boxes([((0.0, -T / 2, 0.0), (0.04, T / 2, 0.04), "B")], hB,
                           max(nA) + 1, eA[-1][0] + 1)
    lines, nC, eC, pface, qface = component.part_lines(a.h, max(nB) + 1, eB[-1][0] + 1)
    out.append("*NODE")
    for nodes in (nA, nB):
        out += [f"{n},{x:.12e},{y:.12e},{z:.12e}" for n, (x, y, z) in nodes.items()]
    out += deck.element_lines(eA, "C3D20R", "FLEXA") + deck.element_lines(eB, "C3D20R", "FLEXB")
    out += lines
    top = max(nC)
    m7, ref5, rot5, ref6, rot6 = top + 1, top + 2, top + 3, top + 4, top + 5
    out.append(f"*NODE\n{m7},{component.NODE7[0]:.9e},{component.NODE7[1]:.9e},{component.NODE7[2]:.9e}")
    out.append(f"{ref5},0.04,0.0,0.0\n{rot5},0.04,0.0,0.0\n{ref6},0.29,0.0,0.0\n{rot6},0.29,0.0,0.0")
    out.append(f"*ELEMENT,TYPE=MASS,ELSET=EMASS\n{eC[-1][0] + 1},{m7}")
    out += [f"*MATERIAL,NAME=STEEL\n*ELASTIC\n{E:.6e},{NU}\n*DENSITY\n{RHO}",
            "*SOLID SECTION,ELSET=FLEXA,MATERIAL=STEEL", "*SOLID SECTION,ELSET=FLEXB,MATERIAL=STEEL",
            f"*MASS,ELSET=EMASS\n{component.MASS}"]
    clamp = deck.on_plane(nA, 1, 0.02) + deck.on_plane(nB, 0, 0.0)
    rig5 = deck.on_plane(nA, 1, -0.02) + deck.on_plane(nB, 0, 0.04) + pface
    out += deck.nset_lines("CLAMP", clamp) + deck.nset_lines("RIG5", rig5)
    out += deck.nset_lines("RIG6", qface + [m7])
    out.append(f"*NSET,NSET=ROT5\n{rot5}\n*NSET,NSET=N7\n{m7}")
    out.append(f"*RIGID BODY,NSET=RIG5,REF NODE={ref5},ROT NODE={rot5}")
    out.append(f"*RIGID BODY,NSET=RIG6,REF NODE={ref6},ROT NODE={rot6}")
    out.append("*BOUNDARY\nCLAMP,1,3")
    incs = max(1, math.ceil(a.incs * abs(value) / 5.0))
    out.append("*STEP,NLGEOM,INC=1000\n*STATIC")
    out.append(f"{1.0 / incs},1.0,1e-6,{1.0 / incs}")
    out.append(f"*BOUNDARY\n{rot5},3,3,{math.radians(value):.12e}")
    if gravity:
        out.append(f"*DLOAD\nFLEXA,GRAV,{G},0.,0.,-1.\nFLEXB,GRAV,{G},0.,0.,-1.\nARM,GRAV,{G},0.,0.,-1.")
        out.append(f"*CLOAD\n{m7},3,{-component.MASS * G:.9e}")
    out.append("*NODE PRINT,NSET=ROT5\nU,RF\n*NODE PRINT,NSET=N7\nU\n*END STEP")
    out.append(f"*STEP,PERTURBATION\n*BOUNDARY,OP=NEW\nCLAMP,1,3\n*FREQUENCY\n{a.modes}\n*END STEP")
    open(path, "w").write("\n".join(out) + "\n")
    return len(nA) + len(nB) + len(nC), len(eA) + len(eB) + len(eC)


def parse(path):
    """(rotation node U3, its reaction RF3, node 7 U3) at the end of the
    static step, and the frequencies of the perturbation step."""
    lines = open(path).read().splitlines()
    # the static step's values come before the eigenvalue output, the last
    # increment's last (the perturbation step prints the sets for every mode)
    end = next((i for i, l in enumerate(lines) if "E I G E N V A L U E   O U T P U T" in l), len(lines))
    got = {}
    for i, l in enumerate(lines[:end]):
        for what, name in (("u", "ROT5"), ("rf", "ROT5"), ("u", "N7")):
            head = "displacements (vx,vy,vz)" if what == "u" else "forces (fx,fy,fz)"
            if l.strip().startswith(f"{head} for set {name}"):
                v = [s for s in lines[i + 1:i + 4] if s.strip()][0].split()
                got[(what, name)] = float(v[3])
    return got.get(("u", "ROT5")), got.get(("rf", "ROT5")), got.get(("u", "N7")), deck.parse_frequencies(path)


def main():
    ap = argparse.ArgumentParser()
    floats = lambda s: [float(x) for x in s.split(",")] if s else []
    ap.add_argument("--phis", type=floats, required=True, help="rotations of node 5 about z (degrees)")
    ap.add_argument("--gravity", action="store_true")
    ap.add_argument("--nl", type=int, default=20)
    ap.add_argument("--nh", type=int, default=20)
    ap.add_argument("--nt", type=int, default=2)
    ap.add_argument("--h", type=float, default=0.005, help="the component's element size (m)")
    ap.add_argument("--modes", type=int, default=8)
    ap.add_argument("--incs", type=int, default=1, help="increments per 5 degrees")
    ap.add_argument("--out", default="/tmp/ch3/mechanism")
    ap.add_argument("--reuse", action="store_true", help="parse existing .dat files in --out, do not run ccx")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    print("case,gravity,phi_set,M,phi_deg,z7,mode,f_Hz", flush=True)
    for v in a.phis:
        job = f"phi{v:+.2f}".replace("+", "p").replace("-", "n").replace(".", "_") + ("g" if a.gravity else "")
        nn, ne = write(os.path.join(a.out, job + ".inp"), a, v, a.gravity)
        print(f"# {job}: {nn} nodes, {ne} elements", file=sys.stderr, flush=True)
        if not a.reuse:
            t0 = time.time()
            deck.run_ccx(job, a.out)
            print(f"# {job}: ccx {time.time() - t0:.0f} s", file=sys.stderr, flush=True)
        rot, m, z7, freqs = parse(os.path.join(a.out, job + ".dat"))
        if len(freqs) != 1 or rot is None or m is None or z7 is None:
            raise SystemExit(f"{job}: static or frequency output missing")
        for k, f in enumerate(freqs[0], 1):
            print(f"solid,mesh={a.nl}x{a.nh}x{a.nt}+h{a.h:g},{int(a.gravity)},{v:g},{m:.9e},{math.degrees(rot):.6f},"
                  f"{z7:.9e},{k},{f:.6f}", flush=True)


if __name__ == "__main__":
    main()
