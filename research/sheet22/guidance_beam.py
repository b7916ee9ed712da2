#!/usr/bin/env python3
"""flexmb sweeps of fixtures/scenes/straight_guidance_spatial.ron with n = 5, 40, 80
beams per flexure, to the strokes of guidance.py (each stroke its own sweep from
0, 5 points, last row). Prints CSV: model,x_S,f1..f6."""
import os, subprocess
F = os.environ.get("FLEXMB", "/work/main/target/release/flexmb")
here = os.path.dirname(os.path.abspath(__file__))
scene = open(os.path.join(here, "..", "..", "fixtures", "scenes", "straight_guidance_spatial.ron")).read()
print("model,x_S,f1,f2,f3,f4,f5,f6")
for n in (5, 40, 80):
    p = f"/tmp/s22/guid_n{n}.ron"
    os.makedirs("/tmp/s22", exist_ok=True)
    open(p, "w").write(scene.replace("n: 5)", f"n: {n})"))
    for x in (0.0, 0.02, 0.04, 0.06, 0.0834):
        d = f"/tmp/s22/fm_guid_n{n}_x{x}"
        to = x if x > 0 else 1e-9
        subprocess.run([F, "sweep", p, "--over", "S.x", "--from", "0", "--to", repr(to), "--n", "5",
                        "--modes", "6", "--out", d], check=True, capture_output=True)
        last = [l for l in open(d + "/eigenfrequencies.csv") if not l.startswith("#")][-1].strip().split(",")
        print(f"flexmb-n{n},{x:g}," + ",".join(f"{float(v):.5f}" for v in last[1:7]))
