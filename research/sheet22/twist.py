#!/usr/bin/env python3
"""Twist along the sheet in the out-of-plane modes of a `sheet.py solid --edges` run.

For each perturbation step and each mode: phi(s) = (u_top - u_bottom) . n(s) / b,
with n the normal of the deformed mid-line in the x-y plane (top/bottom: the
mid-thickness nodes of the edges z = +-b/2); v(s) = mean u_z. A mode is
out-of-plane if its twist or v is larger than its in-plane motion. Prints, per
out-of-plane mode, the share of the twist-rate integral int tau^2 ds that lies
within s < l_frac * L of the clamp (tau = dphi/ds), and tau(0)^2 L / int tau^2.
Usage: python3 twist.py DIR [b] [l]   (l: length of the clamp zone, default 0.233 b)
"""
import re, sys
import numpy as np

d = sys.argv[1]
b = float(sys.argv[2]) if len(sys.argv) > 2 else 0.03
ell = float(sys.argv[3]) if len(sys.argv) > 3 else 0.233 * b
inp = open(d + "/sheet.inp").read()
X = {}
sec = inp.split("*NODE\n", 1)[1].split("*ELEMENT", 1)[0]
for l in sec.splitlines():
    v = l.split(",")
    X[int(v[0])] = np.array([float(x) for x in v[1:4]])
eset = inp.split("*NSET,NSET=EDGES\n", 1)[1].split("*", 1)[0]
edges = [int(x) for x in eset.replace("\n", ",").split(",") if x.strip()]
bot, top = edges[0::2], edges[1::2]
dat = open(d + "/sheet.dat").read()
parts = re.split(r"(?=displacements \(vx,vy,vz\) for set EDGES)|(?=E I G E N V A L U E   O U T P U T)", dat)
static_u, step = None, 0
modes_of_step = []
for p in parts:
    if p.startswith("E I G E N"):
        fs = [float(l.split()[3]) for l in p.splitlines() if len(l.split()) == 5 and l.split()[0].isdigit()]
        modes_of_step.append({"static": static_u, "f": fs, "modes": []})
        in_freq = True
        continue
    if p.startswith("displacements") and "for set EDGES" in p.splitlines()[0]:
        U = {}
        for l in p.splitlines()[1:]:
            v = l.split()
            if len(v) == 4 and v[0].isdigit():
                U[int(v[0])] = np.array([float(x) for x in v[1:]])
        if modes_of_step and len(modes_of_step[-1]["modes"]) < len(modes_of_step[-1]["f"]) and static_u is modes_of_step[-1]["static"]:
            modes_of_step[-1]["modes"].append(U)
        else:
            static_u = U
print("step,mode,f_Hz,kind,share_tau2_within_l,tau0sq_L_over_int,phi_tip_over_max")
for k, st in enumerate(modes_of_step):
    S = st["static"] or {n: np.zeros(3) for n in X}
    pb = np.array([X[n] + S[n] for n in bot]); pt = np.array([X[n] + S[n] for n in top])
    mid = 0.5 * (pb + pt)
    tng = np.gradient(mid[:, :2], axis=0)
    tng /= np.linalg.norm(tng, axis=1)[:, None]
    nrm = np.stack([tng[:, 1], -tng[:, 0]], axis=1)
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(mid[:, :2], axis=0), axis=1))])
    for m, (f, U) in enumerate(zip(st["f"], st["modes"]), 1):
        ub = np.array([U[n] for n in bot]); ut = np.array([U[n] for n in top])
        phi = np.sum((ut - ub)[:, :2] * nrm, axis=1) / b
        v = 0.5 * (ub[:, 2] + ut[:, 2])
        inpl = np.abs(0.5 * (ub + ut)[:, :2]).max()
        out = max(np.abs(phi).max() * b / 2, np.abs(v).max())
        kind = "out" if out > inpl else "in"
        if kind == "in":
            continue
        tau = np.gradient(phi, s)
        t2 = tau ** 2
        tot = np.trapezoid(t2, s)
        near = np.trapezoid(np.where(s <= ell, t2, 0.0), s)
        print(f"{k},{m},{f:.3f},{kind},{near / tot:.4f},{t2[0] * s[-1] / tot:.3f},{phi[-1] / np.abs(phi).max():+.3f}")
