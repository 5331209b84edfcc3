#!/usr/bin/env python3
"""Build designs/data/left-coronary-1d.vtp (and the source file and licence beside it) from SimVascular's svOneDSolver test case of a left coronary tree, and measure it.

Run with a Python that has vtk, numpy and scipy, after fetching the snapshot (GITDIR below: where the `fetch` tool put it):

    python3 scripts/left_coronary_vessel.py

Input (a fetched git snapshot, read with `git show COMMIT:PATH`, never modified):
  * SimVascular/svOneDSolver @ c4b8aac1156764d9faa17b0c9eb1d6a68ca65c85,
    tests/cases/Left_coronary_inlet_pressure_wave_outlet_coronary.in: a 1D (reduced-order) model of a patient's
    left coronary tree, "UNITS IN CGS": NODE cards (x, y, z in cm, points on the vessel centrelines) and SEGMENT
    cards (length, inlet node, outlet node, inlet area, outlet area in cm^2).
  * the same snapshot's Copyright-SimVascular.txt (the repository's licence text).

Outputs (beside this script):
  * svOneDSolver-Left_coronary.in           the source file, byte for byte
  * LICENCE-svOneDSolver-Copyright-SimVascular.txt   the repository's licence text, byte for byte
  * left-coronary-1d.vtp    VTK XML PolyData (inline binary, zlib), coordinates in cm (Float64, the source's
                            values), two polylines, point arrays `Radius` [cm] = sqrt(Area / pi) and `Area` [cm^2]
                            (the source's segment end areas):
                              polyline 0: left main (segment lc1_0) + branch lc1 (lc1_1 ... lc1_19), nodes 0..20
                              polyline 1: left main start (node 0) + branch lc2 (lc2_0 ... lc2_17), nodes 62..80
                                          (node 62, where lc2 starts, lies 0.15 mm from node 1, the left main's end;
                                          node 1 is not repeated)
                            The four side branches (lc1_sub1..3, lc2_sub1) are left out; where they leave is
                            printed below.
  * measurements.txt        what this script prints
"""
import hashlib
import os
import re
import subprocess

import numpy as np
import vtk
from scipy.interpolate import splev, splprep
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "designs", "data")
GITDIR = "/work/.mirror/SimVascular+svOneDSolver/repo"
COMMIT = "c4b8aac1156764d9faa17b0c9eb1d6a68ca65c85"
SOURCE = "tests/cases/Left_coronary_inlet_pressure_wave_outlet_coronary.in"
LICENCE = "Copyright-SimVascular.txt"
OUT_VTP = "left-coronary-1d.vtp"
# the stent segment checked in coronary_stent.yaml: on polyline 0, from s = START to START + LENGTH [mm]
START, LENGTH = 23.0, 18.0
LINES = []


def say(*a):
    line = " ".join(str(x) for x in a)
    print(line)
    LINES.append(line)


def git_show(path, dst, commit=COMMIT):
    data = subprocess.run(["git", "--git-dir", GITDIR, "show", f"{commit}:{path}"], check=True,
                          capture_output=True).stdout
    with open(dst, "wb") as f:
        f.write(data)
    say(f"{os.path.basename(dst)}: {len(data)} bytes, sha256 {hashlib.sha256(data).hexdigest()}"
        f"  <- {path} @ {commit}")
    return data.decode()


def parse(text):
    nodes = {}
    segments = []
    for line in text.splitlines():
        t = line.split()
        if not t:
            continue
        if t[0] == "NODE":
            nodes[int(t[1])] = np.array([float(t[2]), float(t[3]), float(t[4])])
        elif t[0] == "SEGMENT":
            # name, id, length, elements, inlet node, outlet node, inlet area, outlet area, ...
            segments.append(dict(name=t[1], length=float(t[3]), inlet=int(t[5]), outlet=int(t[6]),
                                 a_in=float(t[7]), a_out=float(t[8])))
    return nodes, segments


def branch(nodes, segments, prefix):
    """Node ids and areas along the segments `prefix_0`, `prefix_1`, ...; checks that each segment starts where
    the one before ends, with the same area, and that its length is the distance between its nodes."""
    ss = [s for s in segments if re.fullmatch(re.escape(prefix) + r"_\d+", s["name"])]
    ss.sort(key=lambda s: int(s["name"].rsplit("_", 1)[1]))
    for a, b in zip(ss, ss[1:]):
        assert a["outlet"] == b["inlet"] and abs(a["a_out"] - b["a_in"]) < 1e-12, (a, b)
    for s in ss:
        d = np.linalg.norm(nodes[s["outlet"]] - nodes[s["inlet"]])
        assert abs(d - s["length"]) < 1e-6 * max(1.0, s["length"]), s
    ids = [ss[0]["inlet"]] + [s["outlet"] for s in ss]
    area = [ss[0]["a_in"]] + [s["a_out"] for s in ss]
    return ids, np.array(area)


def arclength(p):
    return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]


def tightest_bend(p, s, a, b, tol):
    """Smallest radius of curvature on [a, b] of a cubic smoothing spline through the points (scipy splprep,
    smoothing so that it stays about `tol` from them), with the fit's largest deviation; the points of a window
    12 units wider on each side are used (the points here are up to 11 mm apart). Cubic, as stentkit fits, not
    quintic: through points this sparse a quintic overshoots."""
    m = (s >= a - 12) & (s <= b + 12)
    q, u = p[m], s[m]
    k = min(3, len(q) - 1)
    tck, _ = splprep(q.T, u=u, s=len(q) * (tol / 2) ** 2, k=k)
    dev = np.max(np.linalg.norm(np.array(splev(u, tck)).T - q, axis=1))
    uu = np.linspace(a, b, 2001)
    d1 = np.array(splev(uu, tck, der=1)).T
    d2 = np.array(splev(uu, tck, der=2)).T
    kap = np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3
    i = int(np.argmax(kap))
    return 1 / kap[i], uu[i], dev, k


def circle_through_nodes(p, s, a, b):
    """Radius of the circle through each three consecutive points whose middle one lies in [a, b]: a fit-free
    figure for points this far apart."""
    out = []
    for i in range(1, len(p) - 1):
        if a <= s[i] <= b:
            A, B, C = p[i - 1], p[i], p[i + 1]
            area2 = np.linalg.norm(np.cross(B - A, C - A))
            r = np.inf if area2 == 0 else (np.linalg.norm(B - A) * np.linalg.norm(C - B) *
                                           np.linalg.norm(A - C) / (2 * area2))
            out.append((r, s[i]))
    return out


def main():
    text = git_show(SOURCE, os.path.join(HERE, "svOneDSolver-Left_coronary.in"))
    git_show(LICENCE, os.path.join(HERE, "LICENCE-svOneDSolver-Copyright-SimVascular.txt"))
    nodes, segments = parse(text)
    say(f"source: {len(nodes)} nodes, {len(segments)} segments")

    lc1, a1 = branch(nodes, segments, "lc1")     # starts with the left main, lc1_0 (nodes 0 -> 1)
    lc2, a2 = branch(nodes, segments, "lc2")     # starts at node 62, next to node 1
    say(f"lc2 starts at node {lc2[0]}, {10 * np.linalg.norm(nodes[lc2[0]] - nodes[lc1[1]]):.2f} mm from node "
        f"{lc1[1]} (the end of the left main, lc1_0)")
    paths = [
        ("polyline 0: left main + lc1", lc1, a1),
        ("polyline 1: left main start + lc2", [lc1[0]] + lc2, np.r_[a1[0], a2]),
    ]

    out = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    lines = vtk.vtkCellArray()
    radius = vtk.vtkDoubleArray()
    radius.SetName("Radius")
    area = vtk.vtkDoubleArray()
    area.SetName("Area")
    geo = []
    for name, ids, a in paths:
        lines.InsertNextCell(len(ids))
        for i, aa in zip(ids, a):
            lines.InsertCellPoint(pts.InsertNextPoint(*nodes[i]))
            radius.InsertNextValue(np.sqrt(aa / np.pi))
            area.InsertNextValue(aa)
        p = np.array([nodes[i] for i in ids])
        geo.append((name, ids, p, np.sqrt(a / np.pi)))
    out.SetPoints(pts)
    out.SetLines(lines)
    out.GetPointData().AddArray(radius)
    out.GetPointData().AddArray(area)
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(os.path.join(HERE, OUT_VTP))
    w.SetInputData(out)
    w.SetDataModeToBinary()
    w.SetCompressorTypeToZLib()
    assert w.Write() == 1
    with open(os.path.join(HERE, OUT_VTP), "rb") as f:
        say(f"{OUT_VTP}: written, sha256 {hashlib.sha256(f.read()).hexdigest()}")

    # read it back: the same numbers
    rd = vtk.vtkXMLPolyDataReader()
    rd.SetFileName(os.path.join(HERE, OUT_VTP))
    rd.Update()
    back = rd.GetOutput()
    allp = np.concatenate([g[2] for g in geo])
    assert np.array_equal(vtk_to_numpy(back.GetPoints().GetData()), allp)
    assert np.array_equal(vtk_to_numpy(back.GetPointData().GetArray("Radius")),
                          np.concatenate([g[3] for g in geo]))

    # where the side branches leave (their first node's nearest node on the two paths)
    side = {}
    for b in ("lc1_sub1", "lc1_sub2", "lc1_sub3", "lc2_sub1"):
        ids, a = branch(nodes, segments, b)
        side[b] = (ids, a)
    for name, ids, p, r in geo:
        s = arclength(p) * 10.0
        say(f"{name}: nodes {ids[0]}, {ids[1]} .. {ids[-1]}; {len(ids)} points, {s[-1]:.1f} mm, "
            f"radius {r.min() * 10:.2f}-{r.max() * 10:.2f} mm, point spacing {np.diff(s).min():.1f}-"
            f"{np.diff(s).max():.1f} mm")
        say("   s [mm]: " + " ".join(f"{x:5.1f}" for x in s))
        say("   r [mm]: " + " ".join(f"{x:5.2f}" for x in r * 10))
        for b, (bids, ba) in side.items():
            d = np.linalg.norm(p - nodes[bids[0]], axis=1)
            j = int(np.argmin(d))
            if d[j] < 0.15:
                say(f"   side branch {b} ({len(bids)} nodes, {arclength(np.array([nodes[i] for i in bids]))[-1] * 10:.1f}"
                    f" mm, radius {np.sqrt(ba[0] / np.pi) * 10:.2f} mm where it starts) leaves at node {ids[j]}, "
                    f"s = {s[j]:.1f} mm ({d[j] * 10:.2f} mm away)")

    # the stent segment on polyline 0
    name, ids, p, r = geo[0]
    pm, rm = p * 10.0, r * 10.0
    s = arclength(pm)
    a, b = START, START + LENGTH
    inside = (s > a) & (s < b)
    ri = np.interp(np.linspace(a, b, 2001), s, rm)
    say(f"segment on polyline 0: s = {a:g}-{b:g} mm, {inside.sum()} source points inside "
        f"(nodes {', '.join(str(ids[i]) for i in np.flatnonzero(inside))}), radius {ri.min():.2f}-{ri.max():.2f} mm "
        f"(linear between nodes), mean {ri.mean():.3f} mm")
    for tol in (0.1, 0.2, 0.5):
        rc, at, dev, k = tightest_bend(pm, s, a, b, tol)
        say(f"  tightest bend of a degree-{k} smoothing spline (max deviation {dev:.2f} mm): R_c = {rc:.1f} mm at "
            f"s = {at:.1f} mm")
    for rc, at in circle_through_nodes(pm, s, a - 3, b + 3):
        say(f"  circle through the node at s = {at:5.1f} mm and its two neighbours: R_c = {rc:.1f} mm")

    with open(os.path.join(HERE, "measurements.txt"), "w") as f:
        f.write("\n".join(LINES) + "\n")


if __name__ == "__main__":
    main()
