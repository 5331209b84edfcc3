#!/usr/bin/env python3
"""Converged limit load of the 215-degree clamped-hinged circular arch (DaDeppo & Schmidt 1975; Simo & Vu-Quoc
1986; Kadapa 2021), by a different method than stentkit's collocation: shooting on the planar Reissner rod
equations under displacement control, which passes the limit point in load.

Problem (designs/arch215.yaml): circle of radius R = 100 about the origin, from -17.5 degrees (clamped) over the
crown at 90 degrees (dead load P along -y) to 197.5 degrees (hinged: position held, free to turn). Section:
EI = 1e6, EA = 2.29e6, GA = EA / 2 (E = 1e6, nu = 0, A = 2.29, I = 1, shear factor 1); and the same arch with
EA = GA = 1e12 (inextensible and unshearable in effect), whose limit load DaDeppo & Schmidt's table gives as
P R^2 / EI = 8.97.

Planar rod equations along the arc length s from the clamp, with x, y the centreline, phi the section angle
(tangent (cos phi, sin phi) in the reference state: phi = theta + pi/2), n = (nx, ny) the spatial force and m the
moment that the part beyond s exerts on the part before it:
    x' = (1 + e) cos phi - g sin phi,  y' = (1 + e) sin phi + g cos phi,  e = N / EA,  g = V / GA,
    N = n . (cos phi, sin phi),  V = n . (-sin phi, cos phi),
    phi' = 1 / R + m / EI,   n' = 0 (n jumps by the crown load),   m' = -(x' ny - y' nx).
Unknowns (nx, ny, m at the clamp; P); equations: the hinge's position, m = 0 there, and the crown's vertical
displacement v. Integrated with DOP853 (rtol = atol = 1e-12), Newton with a central-difference Jacobian; v is
stepped through the limit point and the load's largest value found from the parabola through the three largest
samples (spacing 0.1 of v near the peak). Prints one line per section: `limit EA P_limit_R2_over_EI v u`.
"""
import numpy as np
from scipy.integrate import solve_ivp

R, EI = 100.0, 1.0e6
T0, TC, T1 = np.radians(-17.5), np.radians(90.0), np.radians(197.5)
SC, L = R * (TC - T0), R * (T1 - T0)
XH, YH = R * np.cos(T1), R * np.sin(T1)


def rhs(s, y, n, ea, ga):
    x, yy, phi, m = y
    c, sn = np.cos(phi), np.sin(phi)
    e = (n[0] * c + n[1] * sn) / ea
    g = (-n[0] * sn + n[1] * c) / ga
    dx = (1 + e) * c - g * sn
    dy = (1 + e) * sn + g * c
    return [dx, dy, 1 / R + m / EI, -(dx * n[1] - dy * n[0])]


def residual(u, v, ea, ga):
    nx, ny, m0, p = u
    y0 = [R * np.cos(T0), R * np.sin(T0), T0 + np.pi / 2, m0]
    opts = dict(method="DOP853", rtol=1e-12, atol=1e-12)
    n = np.array([nx, ny])
    crown = solve_ivp(rhs, (0, SC), y0, args=(n, ea, ga), **opts).y[:, -1]
    # The crown force (0, -P) acts on the node: beyond it the section force is n + (0, -P) - ... n(sc+) = n(sc-) - F.
    end = solve_ivp(rhs, (SC, L), crown, args=(n - np.array([0.0, -p]), ea, ga), **opts).y[:, -1]
    r = np.array([end[0] - XH, end[1] - YH, end[3] / EI, crown[1] - (R - v)])
    return r, crown


def limit(ea, ga):
    u = np.zeros(4)
    samples = []
    for v in list(np.arange(2.0, 108.0, 2.0)) + list(np.arange(108.0, 118.0, 0.1)):
        for _ in range(50):
            r, crown = residual(u, v, ea, ga)
            if np.max(np.abs(r)) < 1e-10:
                break
            jac = np.zeros((4, 4))
            for k in range(4):
                h = 1e-6 * max(1.0, abs(u[k]))
                e = np.zeros(4)
                e[k] = h
                jac[:, k] = (residual(u + e, v, ea, ga)[0] - residual(u - e, v, ea, ga)[0]) / (2 * h)
            u = u - np.linalg.solve(jac, r)
        samples.append((v, u[3], crown[0]))
    a = np.array(samples)
    k = int(np.argmax(a[:, 1]))
    c = np.polyfit(a[k - 1 : k + 2, 0], a[k - 1 : k + 2, 1], 2)
    vm = -c[1] / (2 * c[0])
    pm = np.polyval(c, vm)
    um = np.interp(vm, a[k - 1 : k + 2, 0], a[k - 1 : k + 2, 2])
    print(f"limit {ea:.6e} {pm * R * R / EI:.9f} {vm:.6f} {um:.6f}", flush=True)


limit(2.29e6, 0.5e6 * 2.29)
limit(1.0e12, 1.0e12)
