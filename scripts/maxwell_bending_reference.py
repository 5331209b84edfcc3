#!/usr/bin/env python3
"""Independent reference for the rod test "pure bending under time-varying temperature" (issue 4, check 3).

A straight cantilever under a dead end couple M(t) about a fixed axis bends with uniform curvature kappa(t)
(no force, so no stretch or shear; the moment is the same in every section). Its section law is the 1-D
generalized Maxwell model of paper section 2.2 with the WLF shift (Eq. at):
    M(t) / I = E_inf kappa + sum_a E_a (kappa - kappa_a),
    d kappa_a / dt = lambda_a(T(t)) (kappa - kappa_a),   lambda_a = 10**(C1 (T - Tg)/(C2 + T - Tg)) / tau_a,
with frozen relaxation (lambda = 0) at and below T = Tg - C2. Eliminating kappa leaves a linear stiff ODE for the
15 branch curvatures, integrated here with scipy's Radau (implicit, L-stable, order 5) at rtol = 1e-12,
atol = 1e-16 with the exact Jacobian; the stiffest branch has lambda ~ 2e14 1/s at 90 C. The programme
(PLA of paper Table PLA, WLF of Table aT_PLA row 1, d = 0.05 m):
    0     - 0.5 s   T = 90 C, M ramps 0 -> 10 N m     (programming)
    0.5   - 0.75 s  M held, T falls to 31.5 C        (fixing)
    0.75  - 1.0 s   M ramps to 0 at 31.5 C           (release)
    1.0   - 1.625 s nothing changes
    1.625 - 2.5 s   T rises to 90 C                  (recovery), held to 3 s.
Writes tests/data/maxwell_bending_reference.csv: t, kappa (1/m), every 1e-3 s.
Run: python3 scripts/maxwell_bending_reference.py  (numpy, scipy)
"""
import os
import numpy as np
from scipy.integrate import solve_ivp

E_INF = 80.59e6
BRANCHES = [(20.12e6, 1e-10), (50.31e6, 1e-9), (81.37e6, 1e-8), (97.02e6, 1e-7), (173.70e6, 1e-6),
            (225.60e6, 1e-5), (292.64e6, 1e-4), (474.56e6, 1e-3), (449.43e6, 1e-2), (237.98e6, 1e-1),
            (114.16e6, 1e0), (51.82e6, 1e1), (29.98e6, 1e2), (14.40e6, 1e3), (0.72e6, 1e5)]
E = np.array([b[0] for b in BRANCHES])
TAU = np.array([b[1] for b in BRANCHES])
E0 = E_INF + E.sum()
C1, C2, TG = 14.59, 48.43, 70.0
D = 0.05
I = np.pi * D**4 / 64


def table(points):
    t = np.array([p[0] for p in points])
    v = np.array([p[1] for p in points])
    return lambda x: np.interp(x, t, v)


MOMENT = table([(0, 0), (0.5, 10), (0.75, 10), (1.0, 0), (3.0, 0)])
TEMPERATURE = table([(0, 90), (0.5, 90), (0.75, 31.5), (1.625, 31.5), (2.5, 90), (3.0, 90)])
BREAKS = [0.0, 0.5, 0.75, 1.0, 1.625, 2.5, 3.0]


def rates(t):
    x = TEMPERATURE(t) - TG
    if C2 + x <= 0:
        return np.zeros_like(TAU)
    return 10.0 ** (C1 * x / (C2 + x)) / TAU


def kappa_of(t, ka):
    return (MOMENT(t) / I + E @ ka) / E0


def rhs(t, ka):
    return rates(t) * (kappa_of(t, ka) - ka)


def jac(t, ka):
    lam = rates(t)
    return np.outer(lam, E / E0) - np.diag(lam)


def main():
    out = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "maxwell_bending_reference.csv")
    ka = np.zeros(len(E))
    rows = [(0.0, 0.0)]
    for a, b in zip(BREAKS[:-1], BREAKS[1:]):
        times = np.round(np.arange(a, b + 1e-12, 1e-3), 10)
        sol = solve_ivp(rhs, (a, b), ka, method="Radau", jac=jac, rtol=1e-12, atol=1e-16, t_eval=times,
                        first_step=1e-18)
        assert sol.success, sol.message
        for t, y in zip(sol.t[1:], sol.y.T[1:]):
            rows.append((t, kappa_of(t, y)))
        ka = sol.y[:, -1]
    with open(out, "w") as f:
        f.write("# Pure bending of a PLA cantilever under M(t), T(t): uniform curvature from the 1-D Maxwell law.\n")
        f.write("# Made by scripts/maxwell_bending_reference.py (scipy Radau, rtol 1e-12, atol 1e-16).\n")
        f.write("time,kappa\n")
        for t, k in rows:
            f.write(f"{t:.6f},{k:.15e}\n")
    print("wrote", out, len(rows), "rows; kappa max", max(k for _, k in rows), "final", rows[-1][1])


if __name__ == "__main__":
    main()
