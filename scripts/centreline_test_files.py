#!/usr/bin/env python3
"""Writes the centreline test files of tests/data/centrelines/ with VTK's own writers, and the reference values
VTK's own readers give back, for stentkit's centreline reader (tests/stentkit/centreline.rs).

    python3 -m venv /tmp/vtkvenv && /tmp/vtkvenv/bin/pip install vtk
    /tmp/vtkvenv/bin/python scripts/centreline_test_files.py tests/data/centrelines/aorta-centerline.vtp tests/data/centrelines

From the VMTK aorta centreline (409 points, 2 polylines, point array MaximumInscribedSphereRadius) it writes the
same data in every encoding VTK's XML writer has (ascii; inline binary with and without zlib; appended raw with
and without zlib; appended base64; UInt64 headers), with the radius array after two other point arrays, as
legacy VTK (ASCII and binary), with a third polyline, and the bad files a reader must refuse. Each good file gets
`<file>.reference.json`: the polylines as VTK's reader gives them (points in cell order, the radius at those
points), the independent reference of the Rust test.
"""

import json
import math
import sys
from pathlib import Path

import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

RADIUS = "MaximumInscribedSphereRadius"


def read_xml(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def read_legacy(path):
    reader = vtk.vtkPolyDataReader()
    reader.SetFileName(str(path))
    reader.ReadAllScalarsOn()
    reader.ReadAllFieldsOn()
    reader.Update()
    return reader.GetOutput()


def polylines(data):
    """The polylines of `data` as VTK gives them: points in cell order and the radius at them."""
    points = vtk_to_numpy(data.GetPoints().GetData())
    radius = data.GetPointData().GetArray(RADIUS)
    radius = vtk_to_numpy(radius) if radius is not None else None
    lines = data.GetLines()
    ids = vtk.vtkIdList()
    lines.InitTraversal()
    out = []
    while lines.GetNextCell(ids):
        cell = [ids.GetId(k) for k in range(ids.GetNumberOfIds())]
        out.append(
            {
                "points": [[float(x) for x in points[i]] for i in cell],
                "radius": None if radius is None else [float(radius[i]) for i in cell],
            }
        )
    return out


def write_reference(path, data):
    Path(str(path) + ".reference.json").write_text(
        json.dumps({"polylines": polylines(data)}, separators=(",", ":"))
    )


def xml_writer(path, data, mode, compress=True, encode=True, header64=False):
    writer = vtk.vtkXMLPolyDataWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(data)
    {"ascii": writer.SetDataModeToAscii, "binary": writer.SetDataModeToBinary,
     "appended": writer.SetDataModeToAppended}[mode]()
    if compress:
        writer.SetCompressorTypeToZLib()
    else:
        writer.SetCompressorTypeToNone()
    writer.SetEncodeAppendedData(encode)
    if header64:
        writer.SetHeaderTypeToUInt64()
    assert writer.Write() == 1, path


def main(source, out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    data = read_xml(source)
    assert data.GetNumberOfPoints() == 409, data.GetNumberOfPoints()

    good = {
        "aorta_ascii.vtp": dict(mode="ascii"),
        "aorta_binary_raw.vtp": dict(mode="binary", compress=False),
        "aorta_appended_raw.vtp": dict(mode="appended", encode=False),
        "aorta_appended_raw_uncompressed.vtp": dict(mode="appended", compress=False, encode=False),
        "aorta_appended_base64.vtp": dict(mode="appended", encode=True),
        "aorta_uint64.vtp": dict(mode="binary", header64=True),
    }
    for name, options in good.items():
        xml_writer(out / name, data, **options)
        write_reference(out / name, read_xml(out / name))

    # The radius array after two others (VMTK writes more arrays after centreline processing).
    reordered = vtk.vtkPolyData()
    reordered.DeepCopy(data)
    radius = reordered.GetPointData().GetArray(RADIUS)
    reordered.GetPointData().RemoveArray(RADIUS)
    abscissa = vtk.vtkDoubleArray()
    abscissa.SetName("Abscissas")
    tangent = vtk.vtkDoubleArray()
    tangent.SetName("FrenetTangent")
    tangent.SetNumberOfComponents(3)
    for i in range(reordered.GetNumberOfPoints()):
        abscissa.InsertNextValue(0.5 * i)
        tangent.InsertNextTuple3(1.0, 0.0, 0.0)
    reordered.GetPointData().AddArray(abscissa)
    reordered.GetPointData().AddArray(tangent)
    reordered.GetPointData().AddArray(radius)
    xml_writer(out / "aorta_reordered.vtp", reordered, mode="binary")
    write_reference(out / "aorta_reordered.vtp", read_xml(out / "aorta_reordered.vtp"))

    # Legacy files: ASCII and binary, the layout this VTK writes (5.1: OFFSETS/CONNECTIVITY) and 4.2 (counts
    # inline).
    for name, binary, version in [
        ("aorta_legacy_ascii.vtk", False, None),
        ("aorta_legacy_binary.vtk", True, None),
        ("aorta_legacy_42.vtk", False, 42),
    ]:
        writer = vtk.vtkPolyDataWriter()
        writer.SetFileName(str(out / name))
        writer.SetInputData(data)
        if binary:
            writer.SetFileTypeToBinary()
        else:
            writer.SetFileTypeToASCII()
        if version is not None:
            writer.SetFileVersion(version)
        assert writer.Write() == 1, name
        write_reference(out / name, read_legacy(out / name))

    # A third polyline: the first 30 points of line 0 moved by +50 mm in x.
    existing = polylines(data)
    third = {
        "points": [[p[0] + 50.0, p[1], p[2]] for p in existing[0]["points"][:30]],
        "radius": existing[0]["radius"][:30],
    }
    three = vtk.vtkPolyData()
    points = vtk.vtkPoints()
    points.SetDataTypeToDouble()
    radius = vtk.vtkDoubleArray()
    radius.SetName(RADIUS)
    lines = vtk.vtkCellArray()
    for line in existing + [third]:
        ids = []
        for p, r in zip(line["points"], line["radius"]):
            ids.append(points.InsertNextPoint(*p))
            radius.InsertNextValue(r)
        lines.InsertNextCell(len(ids), ids)
    three.SetPoints(points)
    three.SetLines(lines)
    three.GetPointData().AddArray(radius)
    xml_writer(out / "three_lines.vtp", three, mode="binary")
    write_reference(out / "three_lines.vtp", read_xml(out / "three_lines.vtp"))

    # CSV and SimVascular path of polyline 0.
    line0 = polylines(data)[0]
    with open(out / "aorta_line0.csv", "w") as f:
        f.write("x,y,z,radius\n")
        for p, r in zip(line0["points"], line0["radius"]):
            f.write(f"{p[0]!r},{p[1]!r},{p[2]!r},{r!r}\n")
    Path(str(out / "aorta_line0.csv") + ".reference.json").write_text(
        json.dumps({"polylines": [line0]}, separators=(",", ":"))
    )
    path_points = "\n".join(
        f'                    <path_point id="{k}">\n'
        f'                        <pos x="{p[0]!r}" y="{p[1]!r}" z="{p[2]!r}" />\n'
        f'                        <tangent x="1" y="0" z="0" />\n'
        f'                        <rotation x="0" y="1" z="0" />\n'
        f"                    </path_point>"
        for k, p in enumerate(line0["points"])
    )
    control = "\n".join(
        f'                    <point id="{k}" x="{p[0]!r}" y="{p[1]!r}" z="{p[2]!r}" />'
        for k, p in enumerate(line0["points"][::10])
    )
    (out / "aorta_line0.pth").write_text(
        '<?xml version="1.0" encoding="UTF-8" ?>\n<format version="1.0" />\n'
        '<path id="1" method="0" calculation_number="100" spacing="0">\n'
        '    <timestep id="0">\n'
        '        <path_element method="0" calculation_number="100" spacing="0">\n'
        f"            <control_points>\n{control}\n            </control_points>\n"
        f"            <path_points>\n{path_points}\n            </path_points>\n"
        "        </path_element>\n    </timestep>\n</path>\n"
    )
    Path(str(out / "aorta_line0.pth") + ".reference.json").write_text(
        json.dumps({"polylines": [{"points": line0["points"], "radius": None}]}, separators=(",", ":"))
    )

    # Bad files.
    verts_only = vtk.vtkPolyData()
    verts_only.SetPoints(data.GetPoints())
    verts_only.GetPointData().AddArray(data.GetPointData().GetArray(RADIUS))
    verts = vtk.vtkCellArray()
    for i in range(data.GetNumberOfPoints()):
        verts.InsertNextCell(1, [i])
    verts_only.SetVerts(verts)
    xml_writer(out / "no_lines.vtp", verts_only, mode="binary")
    no_radius = vtk.vtkPolyData()
    no_radius.DeepCopy(data)
    no_radius.GetPointData().RemoveArray(RADIUS)
    xml_writer(out / "no_radius.vtp", no_radius, mode="binary")
    nan_point = vtk.vtkPolyData()
    nan_point.DeepCopy(data)
    p = nan_point.GetPoints().GetPoint(100)
    nan_point.GetPoints().SetPoint(100, math.nan, p[1], p[2])
    xml_writer(out / "nan_point.vtp", nan_point, mode="ascii")
    (out / "not_vtk.vtp").write_text("This is a note about a vessel, not a VTK file.\n")
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()}: wrote", ", ".join(sorted(p.name for p in out.iterdir())))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
