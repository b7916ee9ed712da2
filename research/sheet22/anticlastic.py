#!/usr/bin/env python3
"""Anticlastic curvature of a strip in pure bending (Ashwell 1950): the bending
stiffness of a strip of height b, thickness t, bent to curvature kappa, as a
function of Searle's parameter beta = b^2 kappa / t.

Energy per unit length, with u(z) the transverse deflection / kappa (z scaled
to [-1, 1] by the half-height b/2, u by (b/2)^2):
    W = (D b kappa^2 / 2) e,   e = min_u 1/2 int_-1^1 [1 + 2 nu u'' + u''^2 + 4 theta^4 u^2] dz
    theta^4 = 3 (1 - nu^2) beta^2 / 16.
e = 1 - nu^2 (free curl, the beam: W = EI kappa^2/2) at beta = 0 and e -> 1
(the plate, D b) for beta -> infinity.

'exact' minimizes over even Legendre polynomials of degree <= 2N (converged
to 1e-10 for the beta printed); 'ritz' is the one-term parabola of the
element option (u = a (z^2/2 - 1/6)): e = 1 - nu^2 / (1 + (1 - nu^2) beta^2 / 60).

Prints beta, secant factor M/(EI kappa), tangent factor (dM/dkappa)/EI for both.
Usage: python3 anticlastic.py [nu]
"""
import sys
import numpy as np
from numpy.polynomial import legendre as L


def e_exact(beta, nu, N=24):
    th4 = 3.0 * (1.0 - nu * nu) * beta * beta / 16.0
    x, w = L.leggauss(4 * N + 8)
    basis, d2 = [], []
    for n in range(1, N + 1):
        c = np.zeros(2 * n + 1)
        c[2 * n] = 1.0
        basis.append(L.legval(x, c))
        d2.append(L.legval(x, L.legder(c, 2)))
    B, D2 = np.array(basis), np.array(d2)
    # e(a) = 1/2 int [1 + 2 nu D2 a + (D2 a)^2 + 4 th4 (B a)^2]
    H = (D2 * w) @ D2.T + 4.0 * th4 * (B * w) @ B.T
    g = nu * (D2 @ w)
    a = np.linalg.solve(H, -g)
    return 1.0 + g @ a + 0.5 * a @ H @ a


def e_ritz(beta, nu):
    return 1.0 - nu * nu / (1.0 + (1.0 - nu * nu) * beta * beta / 60.0)


def factors(e, beta, nu, h=1e-3):
    """secant W/(EI k^2/2) and tangent (d2W/dk2)/EI, W ~ beta^2 e(beta)."""
    w = lambda b: b * b * e(b, nu)
    sec = e(beta, nu) / (1.0 - nu * nu)
    bb = max(beta, 4 * h)
    tan = (w(bb + h) - 2 * w(bb) + w(bb - h)) / (h * h) / 2.0 / (1.0 - nu * nu)
    if beta == 0:
        tan = 1.0  # the beam: W = EI kappa^2 / 2 exactly (the stencil needs beta > 0)
    return sec, tan


if __name__ == "__main__":
    nu = float(sys.argv[1]) if len(sys.argv) > 1 else 0.3
    print("beta,secant_exact,tangent_exact,secant_ritz,tangent_ritz")
    for beta in [0, 0.5, 1, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 30, 50]:
        se, te = factors(e_exact, beta, nu)
        sr, tr = factors(e_ritz, beta, nu)
        print(f"{beta},{se:.5f},{te:.5f},{sr:.5f},{tr:.5f}")
