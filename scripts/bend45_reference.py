#!/usr/bin/env python3
"""Converged reference for the 45-degree bend of Bathe & Bolourchi (1979), by a different method than
stentkit's collocation: shooting on the static Simo-Reissner rod equations.

Problem: circular arc of radius 100 in the x-y plane, centre (0, 100, 0), from the clamped root (0, 0, 0)
(tangent +x) through 45 degrees; unit square section, E = 1e7, nu = 0 (G = 5e6), shear factor 5/6,
J = 1/6 so that GJ = EI (the benchmark's convention); dead tip force F = (0, 0, 600), no tip couple.

With no distributed load the spatial force is constant, n(s) = F, and the spatial moment is
m(s) = (c(L) - c(s)) x F. Given a guess of the tip position c(L) the rod ODEs
    c' = R Gamma,   Gamma = e1 + C_N^-1 R^T F,
    R' = R hat(K),  K = K0 + C_M^-1 R^T m(s),   K0 = (0, 0, 1/100),
are integrated from the clamp (c = 0, R = I) with an 8th-order Runge-Kutta method (DOP853, rtol = atol = 1e-13);
Newton's method on c_guess -> c(L; c_guess) - c_guess (finite-difference Jacobian) converges to round-off.
Prints the tip displacement c(L) - c0(L).
"""
import numpy as np
from scipy.integrate import solve_ivp

R0 = 100.0
L = R0 * np.pi / 4
E, G = 1.0e7, 5.0e6
A, I, J, KS = 1.0, 1.0 / 12.0, 1.0 / 6.0, 5.0 / 6.0
CN = np.array([E * A, KS * G * A, KS * G * A])
CM = np.array([G * J, E * I, E * I])
F = np.array([0.0, 0.0, 600.0])
K0 = np.array([0.0, 0.0, 1.0 / R0])


def hat(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def rhs(s, y, tip):
    c, R = y[:3], y[3:].reshape(3, 3)
    m = np.cross(tip - c, F)
    gamma = np.array([1.0, 0, 0]) + (R.T @ F) / CN
    kappa = K0 + (R.T @ m) / CM
    return np.concatenate([R @ gamma, (R @ hat(kappa)).ravel()])


def shoot(tip):
    y0 = np.concatenate([np.zeros(3), np.eye(3).ravel()])
    sol = solve_ivp(rhs, (0, L), y0, method="DOP853", rtol=1e-13, atol=1e-13, args=(tip,))
    return sol.y[:3, -1]


tip0 = np.array([R0 * np.sin(np.pi / 4), R0 * (1 - np.cos(np.pi / 4)), 0.0])
tip = tip0.copy()
for it in range(30):
    f = shoot(tip) - tip
    if np.max(np.abs(f)) < 1e-11:
        break
    Jm = np.zeros((3, 3))
    h = 1e-6
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        Jm[:, k] = ((shoot(tip + e) - tip - e) - (shoot(tip - e) - tip + e)) / (2 * h)
    tip = tip - np.linalg.solve(Jm, f)
print("iterations", it, "residual", np.max(np.abs(f)))
print("tip position     %.12f %.12f %.12f" % tuple(tip))
print("tip displacement %.12f %.12f %.12f" % tuple(tip - tip0))
