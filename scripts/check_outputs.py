#!/usr/bin/env python3
"""Independent check of stentkit's run outputs with the official readers (CI runs it after the tests).

Usage: check_outputs.py DIR [DIR ...]

Every DIR is searched recursively. Checked:

* every ``*.mcap`` file, with the official Python ``mcap`` reader: the file is finalised (summary section with
  statistics), the channels ``/state`` and ``/centrelines`` (and ``/device`` if present) have JSON encoding and
  the expected JSON schemas (``stentkit.State``, ``foxglove.SceneUpdate``), message counts agree with the
  statistics (and with the run's ``summary.json``: one ``/state`` per step plus the initial state, one
  ``/device`` per snapshot), log times increase strictly per channel and never decrease in file order, every
  message is valid JSON of its schema's shape (Foxglove scene entities with line strips and indexed triangle
  lists), the design YAML is attached, and a ``stentkit`` metadata record names version, command line and
  units;
* every ``*.stl`` file, with trimesh: watertight, consistently wound, positive volume (and, for snapshots
  listed in a ``summary.json``, the volume stentkit reported, to single precision);
* every run folder (a folder with ``summary.json``): ``history.csv`` has one row per recorded state, the files
  the summary lists exist, and the charts are SVG documents (a run that failed or was interrupted during its
  setup has only its summary, which must say so). A run that was killed and repaired
  (``"status": "killed"``, by ``stentkit repair``) has no charts, and its recording may end a few seconds
  before its history (the recording's chunks are closed every 2 s): it must hold at most, not exactly, one
  ``/state`` per step.

* every shaded picture a run lists among its charts (``charts/configurations.png``), with VTK's ``vtkPNGReader``:
  it reads, and something is drawn;
* every run folder with ``run.pvd`` (the fields for ParaView), with VTK's own ``vtkXMLPolyDataReader`` (the
  ``vtk`` package): the collection lists every snapshot of the summary with its time, strictly increasing;
  every ``.vtp`` reads, holds one polyline per patch and the point arrays stentkit documents with the right
  number of components and tuples and their units (VTK's ``UNITS_LABEL`` information key, in the run's unit
  system), its ``TimeValue`` is the snapshot's time; and its values agree with ``history.csv`` at that time: the
  largest displacement over the polylines' end points (the nodes) with ``max_displacement``, the largest
  surface strain with ``surface_strain_peak``, the displacement at each probe's point with the probe's columns.

Exits with status 1 if anything fails, or if no MCAP file was found at all; prints one line per file and a
closing ``N passed, N failed`` line.
"""

import csv
import itertools
import json
import math
import multiprocessing
import operator
import pathlib
import sys

import numpy as np
import trimesh
from mcap.reader import make_reader

STATE = "/state"
CENTRELINES = "/centrelines"
DEVICE = "/device"
VESSEL = "/vessel"
SCHEMAS = {STATE: "stentkit.State", CENTRELINES: "foxglove.SceneUpdate", DEVICE: "foxglove.SceneUpdate",
           VESSEL: "foxglove.SceneUpdate"}
ENTITY_FIELDS = ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes",
                 "spheres", "cylinders", "lines", "triangles", "texts", "models"]


class Failure(Exception):
    pass


def require(condition, message):
    if not condition:
        raise Failure(message)


def run_summary(folder):
    path = folder / "summary.json"
    if path.is_file():
        return json.loads(path.read_text())
    return None


XYZ = operator.itemgetter("x", "y", "z")
NUMBERS = {int, float}


def check_points(points, topic):
    """Every point is an object with numeric x, y and z (JSON has no NaN: a non-finite value would be null).
    The item lookups and the type tally run in C (itemgetter, map, set): the recordings hold ~10^7 points."""
    try:
        kinds = set(map(type, itertools.chain.from_iterable(map(XYZ, points))))
    except (KeyError, TypeError) as e:
        raise Failure(f"{topic}: a point that is not an object with x, y and z ({type(e).__name__}: {e})") from e
    require(kinds <= NUMBERS, f"{topic}: point coordinates of types {sorted(k.__name__ for k in kinds)}")


def check_scene_update(message, topic):
    require(set(message) >= {"deletions", "entities"}, f"{topic}: SceneUpdate without deletions/entities")
    require(len(message["entities"]) >= 1, f"{topic}: SceneUpdate without entity")
    for entity in message["entities"]:
        missing = [f for f in ENTITY_FIELDS if f not in entity]
        require(not missing, f"{topic}: entity lacks {missing}")
        for line in entity["lines"]:
            # foxglove.LinePrimitive: 0 LINE_STRIP (a rod's centreline), 2 LINE_LIST (the wires' contact pairs,
            # segments of two points each).
            require(line["type"] in (0, 2), f"{topic}: line type {line['type']} is neither LINE_STRIP nor LINE_LIST")
            require(len(line["points"]) >= 2, f"{topic}: line with {len(line['points'])} points")
            require(line["type"] != 2 or len(line["points"]) % 2 == 0,
                    f"{topic}: a LINE_LIST of {len(line['points'])} points (pairs expected)")
            require(line["thickness"] > 0, f"{topic}: line thickness {line['thickness']}")
            check_points(line["points"], topic)
        for tri in entity["triangles"]:
            points, indices = tri["points"], tri["indices"]
            require(len(points) >= 3 and len(indices) % 3 == 0 and len(indices) > 0,
                    f"{topic}: triangle list with {len(points)} points and {len(indices)} indices")
            require(0 <= min(indices) and max(indices) < len(points), f"{topic}: triangle index out of range")
            check_points(points, topic)
    return sum(len(e["lines"]) for e in message["entities"]), sum(len(e["triangles"]) for e in message["entities"])


def check_mcap(path):
    folder = path.parent
    summary_json = run_summary(folder)
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        require(summary is not None and summary.statistics is not None, "no summary section: the file was not finished")
        stats = summary.statistics
        topics = {c.topic: c for c in summary.channels.values()}
        require(STATE in topics and CENTRELINES in topics, f"channels {sorted(topics)}")
        for topic, channel in topics.items():
            require(topic in SCHEMAS, f"unexpected channel {topic}")
            require(channel.message_encoding == "json", f"{topic}: encoding {channel.message_encoding}")
            schema = summary.schemas[channel.schema_id]
            require(schema.name == SCHEMAS[topic], f"{topic}: schema {schema.name}")
            require(schema.encoding == "jsonschema", f"{topic}: schema encoding {schema.encoding}")
            body = json.loads(schema.data)
            require(body.get("type") == "object" and "properties" in body, f"{topic}: schema is not an object schema")

        counts = {t: 0 for t in topics}
        last_per_channel = {}
        last_log_time = -1
        state_times = []
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            topic = channel.topic
            counts[topic] += 1
            t = message.log_time
            require(t >= last_log_time, f"log time {t} after {last_log_time} in file order")
            require(t > last_per_channel.get(topic, -1), f"{topic}: log time {t} not after {last_per_channel.get(topic)}")
            last_log_time = t
            last_per_channel[topic] = t
            data = json.loads(message.data)
            if topic == STATE:
                for key in ("step", "time", "temperature", "iterations", "residual", "probes", "loads"):
                    require(key in data, f"/state lacks {key}")
                require(math.isfinite(data["temperature"]), "/state temperature not finite")
                require(abs(data["time"] * 1e9 - t) <= 1 + 1e-6 * t, f"/state time {data['time']} vs log time {t}")
                state_times.append(data["time"])
            else:
                lines, triangles = check_scene_update(data, topic)
                if topic == VESSEL:
                    require(lines == 1 and triangles == 1, f"{topic}: {lines} lines, {triangles} triangle lists")
                else:
                    require(lines > 0 if topic == CENTRELINES else triangles > 0, f"{topic}: empty scene")

        by_id = {topics[t].id: t for t in topics}
        for channel_id, n in stats.channel_message_counts.items():
            require(counts[by_id[channel_id]] == n, f"{by_id[channel_id]}: {counts[by_id[channel_id]]} messages, statistics say {n}")
        require(sum(counts.values()) == stats.message_count, "message count differs from statistics")
        require(counts[STATE] == counts[CENTRELINES] and counts[STATE] >= 1, f"counts {counts}")
        require(counts.get(VESSEL, 1) == 1, f"{counts.get(VESSEL)} vessel messages, one expected")
        require(all(b > a for a, b in zip(state_times, state_times[1:])), "/state times do not increase")
        if summary_json is not None:
            killed = summary_json["status"] == "killed"
            # A state per step, the initial one and each requested time reached between steps.
            between = summary_json.get("time_error_control", {}).get("requested_states", 0)
            states, snapshots = summary_json["steps"] + 1 + between, len(summary_json["snapshots"])
            require(counts[STATE] <= states if killed else counts[STATE] == states,
                    f"{counts[STATE]} states for {summary_json['steps']} steps")
            if DEVICE in counts:
                require(counts[DEVICE] <= snapshots if killed else counts[DEVICE] == snapshots,
                        f"{counts[DEVICE]} meshes for {snapshots} snapshots")
            require(summary_json["files"]["mcap_bytes"] == path.stat().st_size, "mcap_bytes differs from the file size")

        attachments = list(reader.iter_attachments())
        require(len(attachments) == 1, f"{len(attachments)} attachments")
        design = attachments[0]
        require(design.media_type == "application/yaml", f"attachment type {design.media_type}")
        text = design.data.decode("utf-8")
        require("units:" in text, "the attached design has no `units:`")
        metadata = [m for m in reader.iter_metadata() if m.name == "stentkit"]
        require(len(metadata) == 1, "no `stentkit` metadata record")
        for key in ("stentkit_version", "command_line", "units", "length_unit"):
            require(metadata[0].metadata.get(key), f"metadata lacks {key}")
    return f"{counts} messages, {path.stat().st_size} bytes"




SNAPSHOT_VOLUMES = {}


def check_stl(path):
    mesh = trimesh.load(str(path), force="mesh")
    require(len(mesh.faces) > 0, "no triangles")
    require(mesh.is_watertight, "not watertight")
    require(mesh.is_winding_consistent, "inconsistent winding")
    volume = float(mesh.volume)
    require(volume > 0, f"volume {volume} ≤ 0")
    expected = SNAPSHOT_VOLUMES.get(path.resolve())
    if expected is not None:
        extent = float(np.abs(mesh.vertices).max())
        bound = 4.0 * float(mesh.area) * extent * 2.0 ** -24 + 1e-9 * abs(expected)
        require(abs(volume - expected) <= bound, f"volume {volume} vs {expected} reported (bound {bound:.2e})")
    return f"{len(mesh.faces)} triangles, volume {volume:.6g}"


def check_png(path):
    """The shaded picture: VTK's own PNG reader reads it, RGB(A) 8-bit, with drawn (non-white) pixels."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    data = path.read_bytes()
    # VTK's reader crashes on a cut-off file: check the signature and the closing IEND chunk first.
    require(data[:8] == b"\x89PNG\r\n\x1a\n" and data[-12:-4] == b"\x00\x00\x00\x00IEND",
            f"{path.name}: not a whole PNG file")
    reader = vtk.vtkPNGReader()
    require(reader.CanReadFile(str(path)), f"{path.name}: not a PNG VTK can read")
    reader.SetFileName(str(path))
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    require(width > 0 and height > 0, f"{path.name}: empty picture")
    pixels = vtk_to_numpy(image.GetPointData().GetScalars())
    require(pixels.shape == (width * height, pixels.shape[1]) and pixels.shape[1] in (3, 4), f"{path.name}: {pixels.shape}")
    drawn = int((pixels[:, :3] < 250).any(axis=1).sum())
    require(drawn > 0, f"{path.name}: nothing drawn")
    return drawn


def check_run_folder(folder):
    summary = run_summary(folder)
    for key in ("design", "units", "stentkit_version", "command_line", "wall_time_s", "steps",
                "newton_iterations", "step_cuts", "final_time", "unknowns", "snapshots", "warnings", "notices"):
        require(key in summary, f"summary.json lacks {key}")
    if not (folder / "history.csv").exists():
        # A run that failed or was interrupted while being set up (e.g. a part held by nothing) leaves only its
        # summary, which must say so.
        require(summary["status"] in ("failed", "interrupted") and summary["steps"] == 0 and not summary["snapshots"],
                f"no history.csv, but the summary says {summary['status']} after {summary['steps']} steps")
        return f"{summary['design']}: {summary['status']} during setup: {summary.get('error', '')[:80]}"
    with open(folder / "history.csv", newline="") as f:
        rows = list(csv.reader(f))
    require(rows and rows[0][0] == "time", "history.csv header")
    # A row per state: the initial one, every step, and each requested time an error-controlled run reached
    # between its steps (its continuous extension).
    between = summary.get("time_error_control", {}).get("requested_states", 0)
    require(len(rows) - 1 == summary["steps"] + 1 + between,
            f"history.csv has {len(rows) - 1} rows for {summary['steps']} steps and {between} requested states")
    times = [float(r[0]) for r in rows[1:]]
    # (Non-decreasing: the times are printed to 11 significant digits, which a sliver step may not separate.)
    require(all(a <= b for a, b in zip(times, times[1:])), "history.csv's times decreasing")
    require(summary["snapshots"], "no snapshots")
    steps = [s["step"] for s in summary["snapshots"]]
    require(steps[0] == 0, "no initial snapshot")
    # A snapshot at a requested time between two steps carries the step before it: steps never decrease, times
    # increase.
    require(steps == sorted(steps), "snapshot steps decreasing")
    snapshot_times = [s["time"] for s in summary["snapshots"]]
    require(all(a <= b for a, b in zip(snapshot_times, snapshot_times[1:])), "snapshot times decreasing")
    for s in summary["snapshots"]:
        # The design chooses the mesh formats (STL by default, OBJ on request); each file listed must exist.
        listed = [key for key in ("stl", "obj", "vtp") if key in s]
        require("stl" in listed or "obj" in listed, f"snapshot at step {s['step']} lists no mesh file")
        for key in listed:
            require((folder / s[key]).is_file(), f"missing {s[key]}")
        if "stl" in s:
            SNAPSHOT_VOLUMES[(folder / s["stl"]).resolve()] = s["volume"]
    for chart in summary["files"]["charts"]:
        if chart.endswith(".png"):
            check_png(folder / chart)
            continue
        head = (folder / chart).read_text()[:200]
        require("<svg" in head, f"{chart} is not SVG")
    require(summary["files"]["charts"] or summary["status"] == "killed", "no charts")
    return f"{summary['design']}: {summary['status']}, {summary['steps']} steps, {len(steps)} snapshots"


def field_arrays(units):
    """The point arrays of a field file: name -> (components, unit), for a run in ``units`` (summary.json's)."""
    length, moment, force = units["length"], units["moment"], units["force"]
    return {
        "displacement": (3, length), "rotation": (3, "rad"), "strain": (3, "1"), "curvature": (3, f"1/{length}"),
        "force": (3, force), "moment": (3, moment), "force_spatial": (3, force), "moment_spatial": (3, moment),
        "viscous_strain": (3, "1"), "viscous_curvature": (3, f"1/{length}"), "temperature": (1, "°C"),
        "log10_shift_factor": (1, "1"), "surface_strain": (1, "1"), "arc_length": (1, length),
    }


def check_fields(folder):
    import xml.etree.ElementTree as ElementTree

    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    # A run folder (with summary.json and history.csv) is checked against them; snapshot files written by the
    # library alone (a test's snapshot writer) only for what they hold, in the length unit of their points.
    summary = run_summary(folder)
    entries = [(float(d.get("timestep")), d.get("file"))
               for d in ElementTree.parse(folder / "run.pvd").getroot().iter("DataSet")]
    require(entries, "run.pvd lists no file")
    times = [t for t, _ in entries]
    require(all(a < b for a, b in zip(times, times[1:])), "run.pvd times are not strictly increasing")

    def read(file):
        reader = vtk.vtkXMLPolyDataReader()
        reader.SetFileName(str(folder / file))
        reader.Update()
        return reader.GetOutput()

    def unit_of(array):
        info = array.GetInformation()
        key = vtk.vtkDataArray.UNITS_LABEL()
        return info.Get(key) if info.Has(key) else None

    if summary:
        units = summary["units"]
        snapshots = {s["vtp"]: s["time"] for s in summary["snapshots"] if "vtp" in s}
        require(len(entries) == len(snapshots), f"run.pvd lists {len(entries)} files, the summary {len(snapshots)}")
        with open(folder / "history.csv", newline="") as f:
            rows = list(csv.reader(f))
        header, rows = rows[0], rows[1:]
        column = {name: k for k, name in enumerate(header)}
        probes = [name[:-3] for name in header if name.endswith(".ux")]
    else:
        length = unit_of(read(entries[0][1]).GetPoints().GetData())
        require(length in ("m", "mm"), f"points in {length!r}")
        units = {"length": length, "force": "N", "moment": "N·m" if length == "m" else "N·mm"}
    expected = field_arrays(units)
    for time, file in entries:
        data = read(file)
        n = data.GetNumberOfPoints()
        require(n > 0 and data.GetNumberOfLines() > 0, f"{file}: {n} points, {data.GetNumberOfLines()} lines")
        require(unit_of(data.GetPoints().GetData()) == units["length"], f"{file}: points not in {units['length']}")
        points = data.GetPointData()
        arrays = {}
        for name, (components, unit) in expected.items():
            array = points.GetArray(name)
            require(array is not None, f"{file}: no array {name}")
            require(array.GetNumberOfComponents() == components and array.GetNumberOfTuples() == n,
                    f"{file}: {name} has {array.GetNumberOfComponents()} x {array.GetNumberOfTuples()}")
            require(unit_of(array) == unit, f"{file}: {name} unit {unit_of(array)!r}, not {unit!r}")
            arrays[name] = vtk_to_numpy(array).reshape(n, components)
        field = data.GetFieldData()
        require(abs(vtk_to_numpy(field.GetArray("TimeValue"))[0] - time) <= 1e-12 * max(1.0, abs(time)),
                f"{file}: TimeValue is not {time}")
        if not summary:
            continue
        require(file in snapshots and snapshots[file] == time, f"{file}: time {time} is not the summary's")
        require(data.GetNumberOfLines() == summary["patches"],
                f"{file}: {data.GetNumberOfLines()} lines for {summary['patches']} patches")
        row = min(rows, key=lambda r: abs(float(r[0]) - time))
        require(abs(float(row[0]) - time) <= 1e-9 * max(1.0, abs(time)), f"{file}: no history row at t = {time}")
        value = lambda name: float(row[column[name]])
        # The nodes are the polylines' end points.
        lines = vtk_to_numpy(data.GetLines().GetOffsetsArray())
        ends = sorted({int(k) - 1 for k in lines[1:]} | {int(k) for k in lines[:-1]})
        node_max = float(np.linalg.norm(arrays["displacement"][ends], axis=1).max())
        scale = max(1.0, node_max)
        require(abs(node_max - value("max_displacement")) <= 1e-8 * scale,
                f"{file}: largest node displacement {node_max} vs history {value('max_displacement')}")
        peak = float(arrays["surface_strain"][:, 0].max())
        require(abs(peak - value("surface_strain_peak")) <= 1e-8 * max(1e-3, abs(peak)),
                f"{file}: peak surface strain {peak} vs history {value('surface_strain_peak')}")
        probe_points = field.GetArray("probe_point")
        if probes:
            require(probe_points is not None, f"{file}: no probe_point for {len(probes)} probes")
            for name, point in zip(probes, vtk_to_numpy(probe_points)):
                if point < 0:
                    continue
                u = arrays["displacement"][int(point)]
                h = [value(f"{name}.u{c}") for c in "xyz"]
                require(np.abs(u - h).max() <= 1e-9 * max(1.0, float(np.abs(h).max())),
                        f"{file}: probe {name} displacement {u} vs history {h}")
    if not summary:
        return f"{len(entries)} field files of the snapshot writer (no run folder), {n} points each"
    return f"{summary['design']}: {len(entries)} field files, {n} points each"


CHECKS = {"run": check_run_folder, "mcap": check_mcap, "stl": check_stl, "vtk": check_fields}


def check_one(job):
    """(passed, the line to print) for one (kind, path): every failure is reported, then counted."""
    kind, path = job
    try:
        return True, f"ok    {kind:4} {path}: {CHECKS[kind](path)}"
    except Exception as e:  # noqa: BLE001
        return False, f"FAIL  {kind:4} {path}: {type(e).__name__}: {e}"


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    roots = [pathlib.Path(a) for a in argv[1:]]
    missing = [r for r in roots if not r.is_dir()]
    if missing:
        print(f"not a directory: {', '.join(map(str, missing))}")
        return 1
    folders = sorted({p.parent for r in roots for p in r.rglob("summary.json")})
    mcaps = sorted(p for r in roots for p in r.rglob("*.mcap"))
    stls = sorted(p for r in roots for p in r.rglob("*.stl"))
    fields = sorted(p.parent for r in roots for p in r.rglob("run.pvd"))
    # The run folders first, in this process: they record the snapshot volumes check_stl compares with. The
    # files are independent of each other and checked by two worker processes (CI has two cores), which
    # inherit those volumes; the lines are printed in the same order as one process would print them.
    passed = failed = 0
    jobs = [(kind, path) for kind, paths in (("mcap", mcaps), ("stl", stls), ("vtk", fields)) for path in paths]
    results = [check_one(("run", folder)) for folder in folders]
    with multiprocessing.get_context("fork").Pool(2) as pool:  # forked after the volumes are recorded
        for ok, line in itertools.chain(results, pool.imap(check_one, jobs)):
            passed += ok
            failed += not ok
            print(line, flush=True)
    if not mcaps:
        failed += 1
        print("FAIL  no MCAP file found under " + ", ".join(map(str, roots)))
    print(f"check_outputs: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
