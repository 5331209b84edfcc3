#!/usr/bin/env python3
"""Independent references for rods in pure bending under time-varying temperature (issue 4, check 3; issue 16).

A straight cantilever under a dead end couple M(t) about a fixed axis carries the same moment in every section
(no force, so no stretch or shear). Its section law is the 1-D generalized Maxwell model of paper section 2.2
with the WLF shift (Eq. at):
    M(t) / I = E_inf kappa + sum_a E_a (kappa - kappa_a),
    d kappa_a / dt = lambda_a(T(t)) (kappa - kappa_a),   lambda_a = 10**(C1 (T - Tg)/(C2 + T - Tg)) / tau_a,
with frozen relaxation (lambda = 0) at and below T = Tg - C2. At each section, eliminating kappa leaves a linear
stiff ODE for the branch curvatures, integrated here with scipy's Radau (implicit, L-stable, order 5) at
rtol = 1e-12, atol = 1e-16 with the exact Jacobian; the stiffest branch has lambda ~ 2e14 1/s at 90 C.
The programme (PLA of paper Table PLA, WLF of Table aT_PLA row 1, d = 0.05 m, L = 1 m):
    0     - 0.5 s   T = 90 C, M ramps 0 -> 10 N m     (programming)
    0.5   - 0.75 s  M held, T falls to 31.5 C        (fixing)
    0.75  - 1.0 s   M ramps to 0 at 31.5 C           (release)
    1.0   - 1.625 s nothing changes
    1.625 - 2.5 s   T rises to 90 C                  (recovery), held to 3 s.

Three references, every 1e-3 s:
 1. tests/data/maxwell_bending_reference.csv: t, kappa — one material, uniform temperature (uniform curvature).
 2. tests/data/two_material_bending_reference.csv: t, kappa_a, kappa_b, rotation, x, y — two materials in series,
    x in [0, 1/2) PLA as above, x in [1/2, 1] a second material (the PLA Prony moduli times 0.6, E_inf times 0.6,
    WLF C1 = 17.44, C2 = 51.6, Tg = 60 C: Table aT_PLA's second row with a lower Tg). The curvature is uniform
    in each half; the tip rotation is kappa_a/2 + kappa_b/2 and the tip position (x, y) of the bent beam follows
    from the two circular arcs in closed form.
 3. tests/data/gradient_bending_reference.csv: t, rotation, x, y — one material (PLA) with a temperature that
    varies linearly along the beam, T(x, t) = T(t) + G (x - 1/2), G = 10 K/m. The curvature kappa(x, t) is the
    1-D law at each x; it is computed at 40 Chebyshev points of [0, 1] and interpolated in x (smooth: the
    interpolant's last coefficients are printed, ~1e-12 of the first), integrated once for the rotation
    theta(x) = int_0^x kappa and once more, by 200-point Gauss-Legendre, for the tip position
    (x, y) = int_0^1 (cos theta, sin theta) dx (the undeformed tip is at (1, 0)).
Run: python3 scripts/maxwell_bending_reference.py  (numpy, scipy; about two minutes)
"""
import os
import numpy as np
from numpy.polynomial import chebyshev as C
from scipy.integrate import solve_ivp

PLA_E_INF = 80.59e6
PLA = [(20.12e6, 1e-10), (50.31e6, 1e-9), (81.37e6, 1e-8), (97.02e6, 1e-7), (173.70e6, 1e-6),
       (225.60e6, 1e-5), (292.64e6, 1e-4), (474.56e6, 1e-3), (449.43e6, 1e-2), (237.98e6, 1e-1),
       (114.16e6, 1e0), (51.82e6, 1e1), (29.98e6, 1e2), (14.40e6, 1e3), (0.72e6, 1e5)]
D = 0.05
I = np.pi * D**4 / 64
BREAKS = [0.0, 0.5, 0.75, 1.0, 1.625, 2.5, 3.0]
GRADIENT = 10.0  # K/m


class Material:
    def __init__(self, e_inf, branches, c1, c2, tg):
        self.e = np.array([b[0] for b in branches])
        self.tau = np.array([b[1] for b in branches])
        self.e0 = e_inf + self.e.sum()
        self.c1, self.c2, self.tg = c1, c2, tg


MATERIAL_A = Material(PLA_E_INF, PLA, 14.59, 48.43, 70.0)
MATERIAL_B = Material(0.6 * PLA_E_INF, [(0.6 * e, tau) for e, tau in PLA], 17.44, 51.6, 60.0)


def table(points):
    t = np.array([p[0] for p in points])
    v = np.array([p[1] for p in points])
    return lambda x: np.interp(x, t, v)


MOMENT = table([(0, 0), (0.5, 10), (0.75, 10), (1.0, 0), (3.0, 0)])
TEMPERATURE = table([(0, 90), (0.5, 90), (0.75, 31.5), (1.625, 31.5), (2.5, 90), (3.0, 90)])
TIMES = [np.round(np.arange(a, b + 1e-12, 1e-3), 10) for a, b in zip(BREAKS[:-1], BREAKS[1:])]


def curvature_history(m, offset=0.0):
    """kappa(t) every 1e-3 s of material m at temperature T(t) + offset."""

    def rates(t):
        x = TEMPERATURE(t) + offset - m.tg
        if m.c2 + x <= 0:
            return np.zeros_like(m.tau)
        return 10.0 ** (m.c1 * x / (m.c2 + x)) / m.tau

    def kappa_of(t, ka):
        return (MOMENT(t) / I + m.e @ ka) / m.e0

    def rhs(t, ka):
        return rates(t) * (kappa_of(t, ka) - ka)

    def jac(t, ka):
        lam = rates(t)
        return np.outer(lam, m.e / m.e0) - np.diag(lam)

    ka = np.zeros(len(m.e))
    rows = [(0.0, 0.0)]
    for (a, b), times in zip(zip(BREAKS[:-1], BREAKS[1:]), TIMES):
        sol = solve_ivp(rhs, (a, b), ka, method="Radau", jac=jac, rtol=1e-12, atol=1e-16, t_eval=times,
                        first_step=1e-18)
        assert sol.success, sol.message
        for t, y in zip(sol.t[1:], sol.y.T[1:]):
            rows.append((t, kappa_of(t, y)))
        ka = sol.y[:, -1]
    return np.array(rows)


def arc(kappa, length):
    """End point and end angle of a circular arc of curvature kappa and length `length` from the origin along x."""
    if abs(kappa) < 1e-12:
        return np.array([length, 0.0]), 0.0
    phi = kappa * length
    return np.array([np.sin(phi), 1.0 - np.cos(phi)]) / kappa, phi


def write(name, header, comment, rows):
    out = os.path.join(os.path.dirname(__file__), "..", "tests", "data", name)
    with open(out, "w") as f:
        for line in comment:
            f.write(f"# {line}\n")
        f.write(header + "\n")
        for row in rows:
            f.write(f"{row[0]:.6f}," + ",".join(f"{v:.15e}" for v in row[1:]) + "\n")
    print("wrote", out, len(rows), "rows")


def main():
    made = "Made by scripts/maxwell_bending_reference.py (scipy Radau, rtol 1e-12, atol 1e-16)."
    a = curvature_history(MATERIAL_A)
    write("maxwell_bending_reference.csv", "time,kappa",
          ["Pure bending of a PLA cantilever under M(t), T(t): uniform curvature from the 1-D Maxwell law.", made],
          a)

    b = curvature_history(MATERIAL_B)
    rows = []
    for (t, ka), (_, kb) in zip(a, b):
        p1, phi1 = arc(ka, 0.5)
        p2, phi2 = arc(kb, 0.5)
        c, s = np.cos(phi1), np.sin(phi1)
        tip = p1 + np.array([c * p2[0] - s * p2[1], s * p2[0] + c * p2[1]])
        rows.append((t, ka, kb, phi1 + phi2, tip[0], tip[1]))
    write("two_material_bending_reference.csv", "time,kappa_a,kappa_b,rotation,x,y",
          ["Pure bending of a cantilever of two materials in series (x < 1/2 PLA, x > 1/2 the second material",
           "of the script) under M(t), T(t): curvature per half from each 1-D Maxwell law, tip from two arcs.",
           made], rows)

    nodes = 40
    xs = 0.5 * (1.0 + np.cos(np.pi * (np.arange(nodes) + 0.5) / nodes))  # Chebyshev points of [0, 1]
    kappas = np.array([curvature_history(MATERIAL_A, GRADIENT * (x - 0.5))[:, 1] for x in xs])
    gx, gw = np.polynomial.legendre.leggauss(200)
    gx, gw = 0.5 * (gx + 1.0), 0.5 * gw
    rows, tail = [], 0.0
    for j, t in enumerate(a[:, 0]):
        coeffs = C.chebfit(2.0 * xs - 1.0, kappas[:, j], nodes - 1)
        scale = np.abs(coeffs).max()
        if scale > 0:
            tail = max(tail, np.abs(coeffs[-4:]).max() / scale)
        theta = C.chebint(coeffs, lbnd=-1.0) * 0.5  # d/dx = 2 d/du on u = 2x - 1
        angles = C.chebval(2.0 * gx - 1.0, theta)
        rows.append((t, C.chebval(1.0, theta), gw @ np.cos(angles), gw @ np.sin(angles)))
    print("largest of the last four Chebyshev coefficients relative to the largest:", tail)
    write("gradient_bending_reference.csv", "time,rotation,x,y",
          ["Pure bending of a PLA cantilever under M(t) with T(x, t) = T(t) + 10 K/m (x - 1/2): curvature from",
           "the 1-D Maxwell law at 40 Chebyshev points, rotation and tip position integrated along x.", made],
          rows)


if __name__ == "__main__":
    main()
