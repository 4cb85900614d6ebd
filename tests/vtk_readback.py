#!/usr/bin/env python3
"""Reads every VTK file the io suite wrote back with VTK's own readers (run by hand, not by make).

    make build/check_fsdem && CK_RUN_SUITE=io ./build/check_fsdem   # writes build/test_io_*
    /usr/bin/python3 tests/vtk_readback.py [build]

Needs VTK's Python module (Debian: apt-get install -y python3-vtk9; it installs for the system
python3). For each .vtp (vtkXMLPolyDataReader) and .vti (vtkXMLImageDataReader) it reports the
counts and every point, cell and field array (name, type, components, tuples), fails when VTK prints
an error or warning, when an array's tuple count differs from the points or cells it belongs to, or
when the ascii, binary and appended files of one snapshot do not read back to the same arrays. The
.pvd files are parsed with Python's xml module (vtkPVDReader is ParaView's) and each piece is read.
Exit status 0 when everything reads completely."""
import glob
import os
import sys
import xml.etree.ElementTree as ET

import vtk

folder = sys.argv[1] if len(sys.argv) > 1 else "build"
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL " + msg)


def read(path):
    """The dataset in `path`, read by VTK; None (and a failure) when VTK complains."""
    reader = vtk.vtkXMLPolyDataReader() if path.endswith(".vtp") else vtk.vtkXMLImageDataReader()
    if not reader.CanReadFile(path):
        fail(path + ": the reader cannot read it")
        return None
    log = vtk.vtkStringOutputWindow()  # a fresh log per file: VTK's errors and warnings go there
    vtk.vtkOutputWindow.SetInstance(log)
    reader.SetFileName(path)
    reader.Update()
    text = log.GetOutput()
    if text.strip():
        fail(path + ": VTK said: " + text.strip().replace("\n", " | ")[:400])
        return None
    return reader.GetOutput()


def arrays(data, kind):
    attrs = {"point": data.GetPointData(), "cell": data.GetCellData(), "field": data.GetFieldData()}[kind]
    out = {}
    for k in range(attrs.GetNumberOfArrays()):
        a = attrs.GetAbstractArray(k)
        out[a.GetName()] = a
    return out


def summary(path, data):
    """A description of the dataset, and the arrays by (kind, name) for comparisons."""
    parts, found = [], {}
    if isinstance(data, vtk.vtkPolyData):
        parts.append("points %d verts %d lines %d polys %d" % (data.GetNumberOfPoints(), data.GetNumberOfVerts(),
                                                               data.GetNumberOfLines(), data.GetNumberOfPolys()))
        found[("points", "Points")] = values(data.GetPoints().GetData()) if data.GetPoints() else None
    else:
        parts.append("extent %s cells %d" % (" ".join(map(str, data.GetExtent())), data.GetNumberOfCells()))
    for kind, size in (("point", data.GetNumberOfPoints()), ("cell", data.GetNumberOfCells()), ("field", None)):
        for name, a in sorted(arrays(data, kind).items()):
            desc = "%s %s %s x%d [%d]" % (kind, name, a.GetDataTypeAsString(), a.GetNumberOfComponents(), a.GetNumberOfTuples())
            parts.append(desc)
            if size is not None and a.GetNumberOfTuples() != size:
                fail("%s: %s has %d tuples for %d %ss" % (path, name, a.GetNumberOfTuples(), size, kind))
            found[(kind, name)] = values(a)
    return parts, found


def values(a):
    """Type, components and every tuple of a data array (numpy is not needed)."""
    return (a.GetDataTypeAsString(), a.GetNumberOfComponents(), [a.GetTuple(i) for i in range(a.GetNumberOfTuples())])


def same(a, b):
    return a == b


files = sorted(glob.glob(os.path.join(folder, "test_io_*.vtp")) + glob.glob(os.path.join(folder, "test_io_*.vti")))
if not files:
    fail("no test_io_* files in %s: run the io suite first" % folder)
groups = {}
for path in files:
    data = read(path)
    if data is None:
        continue
    parts, found = summary(path, data)
    print("%s: %s" % (path, "; ".join(parts)))
    stem = path
    for f in ("_ascii.", "_binary.", "_appended."):
        if f in path:
            stem = path.replace(f, ".")
            groups.setdefault(stem, []).append((path, found))
for stem, members in sorted(groups.items()):
    base_path, base = members[0]
    for path, found in members[1:]:
        if set(found) != set(base):
            fail("%s and %s hold different arrays" % (base_path, path))
            continue
        for key in base:
            if not same(base[key], found[key]):
                fail("%s and %s differ in %s %s" % (base_path, path, key[0], key[1]))
    print("%s: %d formats read back to the same arrays" % (stem, len(members)))

for pvd in sorted(glob.glob(os.path.join(folder, "test_io_*.pvd"))):
    try:
        root = ET.parse(pvd).getroot()
    except ET.ParseError as e:
        fail("%s: not XML: %s" % (pvd, e))
        continue
    sets = root.findall("./Collection/DataSet")
    print("%s: %s with %d DataSets" % (pvd, root.get("type"), len(sets)))
    for ds in sets:
        piece = os.path.join(os.path.dirname(pvd), ds.get("file"))
        float(ds.get("timestep"))
        if os.path.exists(piece):
            if read(piece) is not None:
                print("  %s at t = %s: read" % (ds.get("file"), ds.get("timestep")))
        elif "series" not in pvd:  # test_io_series.pvd names pieces that are never written
            fail("%s: piece %s does not exist" % (pvd, piece))

print("%d files, %d failures" % (len(files), len(failures)))
sys.exit(1 if failures else 0)
