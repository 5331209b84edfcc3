#!/usr/bin/env python3
"""Pictures of a run folder's snapshots for the README and assets/ (not part of the tests).

Draws the STL snapshots at the requested times side by side, shaded by a fixed light (matplotlib's 3-D
polygon collection, orthographic view), with the initial shape in light grey behind the first panel and, for a
stent placed on a vessel, the lumen (snapshots/vessel_lumen.stl) as a translucent tube in every panel.
Usage: python3 scripts/render_snapshots.py RUN_DIR OUT.png --times 0 1.75 4 [--view ELEV AZIM] [--title T]
Needs numpy and matplotlib (the STL is read here: 80-byte header, count, 50 bytes per triangle).
"""
import argparse
import json
import os

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402


def read_stl(path):
    data = open(path, "rb").read()
    count = int.from_bytes(data[80:84], "little")
    records = np.frombuffer(data[84:84 + 50 * count], dtype=np.dtype([
        ("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")]))
    return records["vertices"].astype(float)


def shade(triangles, base):
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True) + 1e-300
    light = np.array([0.4, -0.5, 0.75])
    light /= np.linalg.norm(light)
    intensity = 0.35 + 0.65 * np.abs(normals @ light)
    return np.clip(np.outer(intensity, base), 0, 1)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("run")
    parser.add_argument("out")
    parser.add_argument("--times", type=float, nargs="+", required=True)
    parser.add_argument("--view", type=float, nargs=2, default=(20.0, -60.0))
    parser.add_argument("--title", default=None)
    args = parser.parse_args()
    summary = json.load(open(os.path.join(args.run, "summary.json")))
    snapshots = summary["snapshots"]
    lumen_path = os.path.join(args.run, "snapshots", "vessel_lumen.stl")
    lumen = read_stl(lumen_path) if os.path.exists(lumen_path) else None
    initial = read_stl(os.path.join(args.run, snapshots[0]["stl"]))
    chosen = [min(snapshots, key=lambda s: abs(s["time"] - t)) for t in args.times]
    fig = plt.figure(figsize=(4.2 * len(chosen), 4.4))
    # Framed on the device (the lumen may run far beyond it and is clipped).
    lo, hi = initial.reshape(-1, 3).min(axis=0), initial.reshape(-1, 3).max(axis=0)
    centre, half = 0.5 * (lo + hi), 0.55 * (hi - lo).max()
    if lumen is not None:
        inside = np.all(np.abs(lumen - centre).max(axis=1) <= half, axis=1)
        lumen = lumen[inside]
    for k, snap in enumerate(chosen):
        ax = fig.add_subplot(1, len(chosen), k + 1, projection="3d", proj_type="ortho")
        if lumen is not None:
            ax.add_collection3d(Poly3DCollection(lumen, facecolors=(0.85, 0.3, 0.3, 0.06), edgecolors="none"))
        elif k > 0:
            ax.add_collection3d(Poly3DCollection(initial, facecolors=(0.82, 0.82, 0.82, 0.25), edgecolors="none"))
        triangles = read_stl(os.path.join(args.run, snap["stl"]))
        ax.add_collection3d(Poly3DCollection(triangles, facecolors=shade(triangles, np.array([0.25, 0.35, 0.6])),
                                             edgecolors="none"))
        for axis, set_lim in enumerate([ax.set_xlim, ax.set_ylim, ax.set_zlim]):
            set_lim(centre[axis] - half, centre[axis] + half)
        ax.set_box_aspect((1, 1, 1), zoom=1.5)
        ax.view_init(*args.view)
        ax.set_axis_off()
        ax.set_title(f"t = {snap['time']:.3g} s", fontsize=11)
    if args.title:
        fig.suptitle(args.title, fontsize=12)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
