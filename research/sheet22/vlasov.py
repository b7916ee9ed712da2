#!/usr/bin/env python3
"""First torsion frequency of a clamped-free strip, St-Venant vs Vlasov
(warping restrained at the clamp, free at the tip), as a closed-form check of
the solid-vs-beam difference at rest.

  EIw phi'''' - GJ phi'' = w^2 rho Ip phi,  phi(0)=phi'(0)=0, phi''(L)=0, GJ phi'(L)-EIw phi'''(L)=0
EIw = E b^3 t^3/144 is the warping rigidity of a thin rectangle (plate bending
D = E t^3/12 acting on w_n = z*phi; Vlasov's secondary warping constant).
J from the series for a rectangle (Timoshenko & Goodier), as flexmb uses.
Usage: python3 vlasov.py [b t L G/E]
"""
import math, sys
import numpy as np

def J_rect(b, t, terms=50):
    a, c = max(b, t), min(b, t)
    s = sum(math.tanh((2*n+1)*math.pi*a/(2*c))/(2*n+1)**5 for n in range(terms))
    return a*c**3/3*(1 - 192/math.pi**5*c/a*s)

def f_torsion(b, t, L, E=2.1e11, G=2.1e11/2.6, rho=7600.0, warping=True):
    GJ = G*J_rect(b, t); Ip = rho*(b*t**3 + t*b**3)/12
    if not warping:
        return math.sqrt(GJ/Ip)*math.pi/(2*L)/(2*math.pi)
    EIw = E*b**3*t**3/144
    def det(w):
        # k^2 roots of EIw k^4 - GJ k^2 - w^2 Ip = 0
        disc = math.sqrt(GJ**2 + 4*EIw*w*w*Ip)
        a = math.sqrt((GJ + disc)/(2*EIw)); bb = math.sqrt((disc - GJ)/(2*EIw))
        # basis cosh(a s), sinh(a s), cos(bb s), sin(bb s) written with decaying
        # exponentials for conditioning: e^{-a s}, e^{-a (L-s)}, cos, sin
        def rows(s):
            funcs = []
            for kind in range(4):
                if kind == 0:   # e^{-a s}
                    v = [math.exp(-a*s)*(-a)**d for d in range(4)]
                elif kind == 1: # e^{-a (L-s)}
                    v = [math.exp(-a*(L-s))*a**d for d in range(4)]
                elif kind == 2:
                    v = [math.cos(bb*s), -bb*math.sin(bb*s), -bb**2*math.cos(bb*s), bb**3*math.sin(bb*s)]
                else:
                    v = [math.sin(bb*s), bb*math.cos(bb*s), -bb**2*math.sin(bb*s), -bb**3*math.cos(bb*s)]
                funcs.append(v)
            return np.array(funcs).T  # [derivative][basis]
        r0, rL = rows(0.0), rows(L)
        M = np.array([r0[0], r0[1], rL[2], GJ*rL[1] - EIw*rL[3]])
        M = M/np.abs(M).max(axis=1, keepdims=True)
        return np.linalg.det(M)
    w0 = 2*math.pi*f_torsion(b, t, L, E, G, rho, False)
    ws = np.linspace(0.9*w0, 1.3*w0, 4001)
    d = [det(w) for w in ws]
    for i in range(len(ws)-1):
        if d[i]*d[i+1] < 0:
            lo, hi = ws[i], ws[i+1]
            for _ in range(60):
                mid = 0.5*(lo+hi)
                if det(lo)*det(mid) <= 0: hi = mid
                else: lo = mid
            return 0.5*(lo+hi)/(2*math.pi)
    return float('nan')

if __name__ == "__main__":
    b, t, L = 0.03, 0.001, 0.2
    if len(sys.argv) > 3:
        b, t, L = map(float, sys.argv[1:4])
    g = float(sys.argv[4]) if len(sys.argv) > 4 else 1/2.6
    f0 = f_torsion(b, t, L, G=2.1e11*g, warping=False); f1 = f_torsion(b, t, L, G=2.1e11*g)
    print(f"b={b} t={t} L={L} G/E={g:.4f}: St-Venant {f0:.3f} Hz, Vlasov (clamp warping restrained) {f1:.3f} Hz, ratio {f1/f0:.4f}")
