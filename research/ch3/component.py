#!/usr/bin/env python3
"""The complex-shaped component of thesis §3.5.2 (Table 3.1) as a CalculiX
solid: the FE reference of the superelements SE-C, SE-CF1, SE-CF2 and SE-CF6
in `cargo xtask reproduce ch3` (issue 16).

Fig. 3.12, which held the part's geometry, is lost; this is our design, the
same as xtask/src/ch3/component.rs (`Geometry::default()`, documented in
docs/reproduce.md): a flat, hollow aluminium arm along x from node 5
(0.04, 0, 0) to node 6 (0.29, 0, 0) of Table 3.2, a rectangular tube 30 mm
wide (y) and 3.7 mm high (z) with 1 mm walls, solid 10 mm end blocks whose
outer faces are the two interfaces, and two 1 mm bulkheads (ribs) inside at a
third and two thirds of the tube. E = 7.0e10 Pa, nu = 0.33, rho = 2700.
The mesh is flexmb's (research/ch3/deck.py repeats its algorithm) with
C3D20 elements (full integration, as flexmb's built-in hexahedra), so the
superelements and this model share their elements.

The face x = 0.04 is clamped; the face x = 0.29 and the 0.01 kg mass node 7
(0.29, -0.1, 0) form one *RIGID BODY (the massless rigid link of the thesis
and its "interface surfaces modelled rigidly"). One *FREQUENCY step.

Usage: python3 component.py [--h 0.005] [--modes 10] [--out DIR]
Prints CSV: case,h,mode,f_Hz
"""
import argparse, os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import deck

X5, X6 = 0.04, 0.29
NODE7 = (0.29, -0.1, 0.0)
MASS = 0.01
WIDTH, HEIGHT, WALL, END, RIBS = 0.03, 0.0037, 1e-3, 0.01, (1.0 / 3.0, 2.0 / 3.0)
E, NU, RHO = 7.0e10, 0.33, 2700.0


def blocks():
    """The boxes of the part, in the order of component.rs `blocks`."""
    w, h, t = 0.5 * WIDTH, 0.5 * HEIGHT, WALL
    a0, a1 = X5 + END, X6 - END
    v = [((X5, -w, -h), (a0, w, h)), ((a1, -w, -h), (X6, w, h)),
         ((a0, -w, h - t), (a1, w, h)), ((a0, -w, -h), (a1, w, -h + t)),
         ((a0, -w, -h + t), (a1, -w + t, h - t)), ((a0, w - t, -h + t), (a1, w, h - t))]
    for f in RIBS:
        xr = a0 + f * (a1 - a0)
        v.append(((xr - 0.5 * t, -w + t, -h + t), (xr + 0.5 * t, w - t, h - t)))
    return [(lo, hi, "ARM") for lo, hi in v]


def part_lines(h, first_node=1, first_element=1, etype="C3D20"):
    """The part's nodes, elements, material and section, and its clamp and
    rigid-face node sets: (lines, nodes, elements, p face, q face)."""
    nodes, elems = deck.boxes(blocks(), (h, h, h), first_node, first_element)
    out = ["*NODE"] + [f"{n},{x:.12e},{y:.12e},{z:.12e}" for n, (x, y, z) in nodes.items()]
    out += deck.element_lines(elems, etype, "ARM")
    out += [f"*MATERIAL,NAME=ALU\n*ELASTIC\n{E:.6e},{NU}\n*DENSITY\n{RHO}",
            "*SOLID SECTION,ELSET=ARM,MATERIAL=ALU"]
    return out, nodes, elems, deck.on_plane(nodes, 0, X5), deck.on_plane(nodes, 0, X6)


def write(path, a):
    out = ["*HEADING", f"thesis 3.5.2 component, h = {a.h}"]
    lines, nodes, elems, pface, qface = part_lines(a.h)
    out += lines
    top = max(nodes)
    m7, ref, rot = top + 1, top + 2, top + 3
    out.append(f"*NODE\n{m7},{NODE7[0]:.9e},{NODE7[1]:.9e},{NODE7[2]:.9e}")
    out.append(f"{ref},{X6:.9e},0.0,0.0\n{rot},{X6:.9e},0.0,0.0")
    out.append(f"*ELEMENT,TYPE=MASS,ELSET=EMASS\n{max(e for e, _, _ in elems) + 1},{m7}")
    out += deck.nset_lines("CLAMP", pface) + deck.nset_lines("RIGQ", qface + [m7])
    out.append(f"*MASS,ELSET=EMASS\n{MASS}")
    out.append(f"*RIGID BODY,NSET=RIGQ,REF NODE={ref},ROT NODE={rot}")
    out.append("*BOUNDARY\nCLAMP,1,3")
    out.append(f"*STEP\n*FREQUENCY\n{a.modes}\n*END STEP")
    open(path, "w").write("\n".join(out) + "\n")
    return len(nodes), len(elems)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--h", type=float, default=0.005, help="largest element size (m)")
    ap.add_argument("--modes", type=int, default=10)
    ap.add_argument("--out", default="/tmp/ch3/component")
    ap.add_argument("--reuse", action="store_true", help="parse an existing .dat in --out, do not run ccx")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    job = "component"
    nn, ne = write(os.path.join(a.out, job + ".inp"), a)
    print(f"# {job}: {nn} nodes, {ne} elements", file=sys.stderr)
    if not a.reuse:
        deck.run_ccx(job, a.out)
    steps = deck.parse_frequencies(os.path.join(a.out, job + ".dat"))
    if len(steps) != 1:
        raise SystemExit(f"{job}: {len(steps)} frequency steps parsed, 1 expected")
    print("case,h,mode,f_Hz")
    for k, f in enumerate(steps[0], 1):
        print(f"solid C3D20,{a.h:g},{k},{f:.6f}")


if __name__ == "__main__":
    main()
