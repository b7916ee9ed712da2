#!/usr/bin/env python3
"""flexmb sweeps of fixtures/scenes/straight_guidance_spatial.ron with n = 5, 40, 80
beams per flexure, to the strokes of guidance.py (each stroke its own sweep from
0, 5 points, last row). Prints CSV: model,x_S,f1..f6.

  guidance_beam.py --warping [n ...]   (issue 22 item 3)
gives the flexures the beam option `warping`, restrained at the base clamps and
at the body (default n = 5, 20, 40), and adds the columns sweep_s (wall time of
the sweep; the machine's 2 cores are shared, so indicative only).
  guidance_beam.py --anticlastic [n ...]   (the Poisson share, ν = 0.3)
adds the option `anticlastic`, restrained at both ends, to the warping beams."""
import os, subprocess, sys, time
F = os.environ.get("FLEXMB", "/work/main/target/release/flexmb")
here = os.path.dirname(os.path.abspath(__file__))
scene = open(os.path.join(here, "..", "..", "fixtures", "scenes", "straight_guidance_spatial.ron")).read()
anticlastic = "--anticlastic" in sys.argv
warping = "--warping" in sys.argv or anticlastic
ns = [int(v) for v in sys.argv[1:] if not v.startswith("--")] or ([5, 20, 40] if warping else [5, 40, 80])
tag, opt = ("flexmb-warping", ", warping: Some((p: Restrained, q: Restrained))") if warping else ("flexmb", "")
if anticlastic:
    tag, opt = "flexmb-anticlastic", opt + ", anticlastic: Some((p: Restrained, q: Restrained))"
print("model,x_S,f1,f2,f3,f4,f5,f6" + (",sweep_s" if warping else ""))
for n in ns:
    w = ('a' if anticlastic else 'w') if warping else ''
    p = f"/tmp/s22/guid{w}_n{n}.ron"
    os.makedirs("/tmp/s22", exist_ok=True)
    open(p, "w").write(scene.replace("n: 5)", f"n: {n}{opt})"))
    for x in (0.0, 0.02, 0.04, 0.06, 0.0834):
        d = f"/tmp/s22/fm_guid{w}_n{n}_x{x}"
        to = x if x > 0 else 1e-9
        t0 = time.time()
        subprocess.run([F, "sweep", p, "--over", "S.x", "--from", "0", "--to", repr(to), "--n", "5",
                        "--modes", "6", "--out", d], check=True, capture_output=True)
        last = [l for l in open(d + "/eigenfrequencies.csv") if not l.startswith("#")][-1].strip().split(",")
        wall = f",{time.time() - t0:.2f}" if warping else ""
        print(f"{tag}-n{n},{x:g}," + ",".join(f"{float(v):.5f}" for v in last[1:7]) + wall, flush=True)
