"""A first tour of flexmb from Python.

1. The spatial straight guidance of thesis §6.4: its four lowest
   eigenfrequencies along the load, the curve of Fig. 6.9, plotted with
   matplotlib (if installed) and checked against the stored curve
   fixtures/curves/ch6/unreduced.csv.
2. A pendulum built from Python dicts: its period against the exact
   large-amplitude period 2π √(l/g) / AGM(1, cos(θ0/2)).
3. A modal reduced model of the planar guidance: fewer evaluations for the
   same slow response.

Run from anywhere:  python python/examples/tutorial.py [OUTPUT_DIR]
(the figure goes to OUTPUT_DIR, default target/python-tutorial). Exits with
status 1 if a result is off.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import flexmb

ROOT = Path(__file__).resolve().parents[2]


def guidance_sweep(out: Path) -> float:
    """The eigenfrequencies of the spatial guidance over the load scale;
    returns the largest relative difference from the stored curve."""
    scene = flexmb.Scene.load(ROOT / "fixtures" / "scenes" / "straight_guidance_spatial.ron")
    model = flexmb.Model(scene)
    info = model.info()
    print(f"{info['name']}: {info['n_dof']} degrees of freedom")

    # the stored curve: load scale, x of S, f1..f4
    lines = (ROOT / "fixtures" / "curves" / "ch6" / "unreduced.csv").read_text().splitlines()
    rows = [line for line in lines if line.strip() and not line.startswith("#")][1:]
    stored = np.array([[float(v) for v in row.split(",")] for row in rows])
    lam = stored[:, 0]
    # the scene's x-force acts at t = 0.05 s; the sweep scales it by lam
    # a tqdm bar on a terminal (if tqdm is installed)
    sweep = model.sweep(over="load", values=lam, modes=4, t_load=0.05, progress=sys.stderr.isatty())
    f = sweep.frequencies  # shape (61, 4), Hz
    worst = float(np.abs(f / stored[:, 2:6] - 1).max())
    print(f"{len(lam)} load scales, f1 from {f[:, 0].min():.3f} to {f[:, 0].max():.3f} Hz; "
          f"largest relative difference from the stored curve {worst:.1e}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure (pip install matplotlib)")
        return worst
    fig, ax = plt.subplots(figsize=(6, 4))
    for k in range(f.shape[1]):
        ax.plot(lam, f[:, k], label=f"mode {k + 1}")
    ax.set_xlabel("load scale λ")
    ax.set_ylabel("eigenfrequency (Hz)")
    ax.set_yscale("log")
    ax.set_title("spatial straight guidance (thesis Fig. 6.9)")
    ax.legend()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "guidance_sweep.png", dpi=120, bbox_inches="tight")
    print(f"wrote {out / 'guidance_sweep.png'}")
    return worst


def agm(a: float, b: float) -> float:
    """The arithmetic-geometric mean."""
    while abs(a - b) > 1e-15 * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return a


def pendulum() -> float:
    """A 1 m rigid massless rod with a 2 kg bob released at rest 1 rad from
    hanging; returns the relative error of its period."""
    l, g, theta0 = 1.0, 9.81, 1.0
    scene = flexmb.Scene.from_dict({
        "dimension": "Planar",
        "gravity": [0.0, -g],
        "materials": {"m": {"e": 1.0e9, "rho": 0.0}},
        "sections": {"s": {"Circle": {"d": 0.01}}},
        "nodes": [{"id": "A", "at": [0.0, 0.0]},
                  {"id": "B", "at": [l * math.sin(theta0), -l * math.cos(theta0)]}],
        "elements": [
            {"id": "rod", "type": {"Beam": {"nodes": ["A", "B"], "material": "m", "section": "s", "mass": False}}},
            {"id": "bob", "type": {"PointMass": {"node": "B", "mass": 2.0}}},
        ],
        "fixed": [{"Coord": ["A", "Position"]}],
        "rigid": [{"Def": ["rod", "*"]}],
        "outputs": [{"Position": "B"}],
    })
    r = flexmb.Model(scene).simulate(t_end=4.5, outputs=9001, rtol=1e-10, atol=1e-12)
    theta = np.arctan2(r.outputs["B.x"], -r.outputs["B.y"])
    i = np.nonzero((theta[:-1] < 0) & (theta[1:] >= 0))[0]
    crossings = r.t[i] + (r.t[i + 1] - r.t[i]) * theta[i] / (theta[i] - theta[i + 1])
    period = crossings[1] - crossings[0]
    small = 2 * math.pi * math.sqrt(l / g)
    exact = small / agm(1.0, math.cos(theta0 / 2))
    error = abs(period / exact - 1)
    print(f"pendulum: period {period:.6f} s, exact {exact:.6f} s (small-amplitude {small:.6f} s), "
          f"relative error {error:.1e}, {r.rhs_evals} evaluations")
    return error


def reduced() -> bool:
    """MODAL-3 of the planar guidance against all its degrees of freedom."""
    model = flexmb.Model(flexmb.Scene.load(ROOT / "fixtures" / "scenes" / "straight_guidance_planar.ron"))
    red = model.reduce(method="modal", modes=3)
    full = model.simulate(t_end=0.1, outputs=11)
    fast = red.simulate(t_end=0.1, outputs=11)
    print(f"planar guidance, 0.1 s: {full.rhs_evals} evaluations with {model.info()['n_dof']} "
          f"degrees of freedom, {fast.rhs_evals} with MODAL-3 ({red.description})")
    print(f"  S.x at 0.1 s: {full.outputs['S.x'][-1]:.6e} m unreduced, {fast.outputs['S.x'][-1]:.6e} m reduced")
    return fast.rhs_evals < full.rhs_evals


def main() -> int:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "python-tutorial"
    ok = True
    if guidance_sweep(out) > 1e-6:
        print("the sweep differs from the stored curve by more than 1e-6", file=sys.stderr)
        ok = False
    if pendulum() > 1e-6:
        print("the pendulum period is off by more than 1e-6", file=sys.stderr)
        ok = False
    if not reduced():
        print("the reduced model took no fewer evaluations", file=sys.stderr)
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
