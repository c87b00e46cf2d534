"""Reads fibercell's VTK files with VTK itself (the library ParaView is built on, from PyPI)
and runs the filters a user would: Warp By Vector on the displacement and Tube on the radius.

    python3 tests/vtk/check_vtk.py path/to/fibercell

Prints one `test result:` line in cargo's format (counted by .ci/run) and exits non-zero on a
failure.
"""

import json
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import vtk
from vtk.util.numpy_support import vtk_to_numpy

FIBERCELL = sys.argv[1]
passed, failed = 0, 0


def run(*args):
    subprocess.run([FIBERCELL, *args], check=True, capture_output=True)


def read(path):
    reader = (
        vtk.vtkXMLPolyDataReader()
        if str(path).endswith(".vtp")
        else vtk.vtkXMLUnstructuredGridReader()
    )
    reader.SetFileName(str(path))
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise AssertionError(f"{path}: VTK reader error {reader.GetErrorCode()}")
    return reader.GetOutput()


def check(name, test):
    global passed, failed
    try:
        test()
        passed += 1
        print(f"test {name} ... ok")
    except Exception as e:  # noqa: BLE001 - every failure is reported, then counted
        failed += 1
        print(f"test {name} ... FAILED: {e!r}")


def point_array(data, name):
    array = data.GetPointData().GetArray(name)
    assert array is not None, f"no point data {name}"
    return vtk_to_numpy(array)


tmp = Path(tempfile.mkdtemp())


def network_warps_to_the_deformed_frame():
    """Reference points + displacement = the solution; Warp By Vector moves them once."""
    for encoding in ["ascii", "binary"]:
        out = tmp / f"frame_{encoding}"
        run("solve", "fixtures/ok_frame3d.toml", "-d", str(out), "--vtk", encoding)
        data = read(out / "network.vtp")
        doc = json.loads((out / "displacements.json").read_text())
        assert data.GetNumberOfPoints() == 7 and data.GetNumberOfLines() == 3
        u = point_array(data, "displacement")
        ids = point_array(data, "node_id")
        x = vtk_to_numpy(data.GetPoints().GetData())
        warp = vtk.vtkWarpVector()
        warp.SetInputData(data)
        warp.SetInputArrayToProcess(0, 0, 0, 0, "displacement")
        warp.Update()
        warped = vtk_to_numpy(warp.GetOutput().GetPoints().GetData())
        reference = {
            n["id"]: n["x"]
            for n in tomllib.loads(Path("fixtures/ok_frame3d.toml").read_text())["nodes"]
        }
        for k, node in enumerate(ids):
            want = doc["displacements"][str(node)][:3]
            assert list(u[k]) == want, (node, list(u[k]), want)
            # The file's points are the model's reference coordinates, so the warp moves
            # them by the displacement once.
            assert list(x[k]) == reference[node], (node, list(x[k]), reference[node])
            moved = [r + d for r, d in zip(reference[node], want)]
            assert (abs(warped[k] - moved) <= 1e-15 * (1 + abs(warped[k]))).all()
        assert abs(u).max() > 0


def binary_and_text_hold_the_same_numbers():
    a = read(tmp / "frame_ascii" / "network.vtp")
    b = read(tmp / "frame_binary" / "network.vtp")
    for name in ["displacement", "rotation", "radius", "node_id"]:
        assert (point_array(a, name) == point_array(b, name)).all(), name
    assert (
        vtk_to_numpy(a.GetPoints().GetData()) == vtk_to_numpy(b.GetPoints().GetData())
    ).all()


def tube_filter_takes_the_fibers_directly():
    out = tmp / "cell"
    out.mkdir()
    run("convert", "fixtures/cells/woven_small.toml", str(out / "cell.pvd"))
    data = read(out / "cell_fibers.vtp")
    data.GetPointData().SetActiveScalars("radius")
    tube = vtk.vtkTubeFilter()
    tube.SetInputData(data)
    tube.SetVaryRadiusToVaryRadiusByAbsoluteScalar()
    tube.SetNumberOfSides(8)
    tube.Update()
    surface = tube.GetOutput()
    assert surface.GetNumberOfPolys() + surface.GetNumberOfStrips() > 0
    # The tube's width is the fibers' diameter, not a default.
    radius = point_array(data, "radius").max()
    bounds = surface.GetBounds()
    lo = data.GetBounds()
    assert abs((lo[4] - bounds[4]) - radius) <= 1e-3 * radius, (bounds, lo, radius)
    contacts = read(out / "cell_contacts.vtp")
    assert contacts.GetNumberOfVerts() == contacts.GetNumberOfPoints() > 0
    assert set(point_array(contacts, "state")) <= {0, 1}


def unstructured_grid_has_poly_line_cells():
    out = tmp / "grid.vtu"
    run("convert", "fixtures/ok_frame3d.toml", str(out), "--vtk", "binary")
    data = read(out)
    assert data.GetNumberOfCells() == 3
    assert all(data.GetCellType(c) == vtk.VTK_POLY_LINE for c in range(3))


def a_contact_series_reads_step_by_step():
    out = tmp / "bars"
    run("solve", "fixtures/ok_contact_bars2.toml", "--steps", "4", "-o", str(out))
    collection = (out / "solution.pvd").read_text()
    files = [part.split('"')[0] for part in collection.split('file="')[1:]]
    assert len(files) == 8
    for f in files:
        read(out / f)
    contacts = read(out / "contacts_0004.vtp")
    assert abs(point_array(contacts, "normal_force")[0] - 2.0) < 1e-9


def cell_problems_read():
    out = tmp / "homogenized"
    run("homogenize", "fixtures/cells/woven_small.toml", "--out-dir", str(out))
    for case in ["e11", "e22", "g12", "k11", "k22", "k12", "pressure"]:
        data = read(out / f"case_{case}.vtp")
        assert abs(point_array(data, "displacement")).max() > 0, case


for test in [
    network_warps_to_the_deformed_frame,
    binary_and_text_hold_the_same_numbers,
    tube_filter_takes_the_fibers_directly,
    unstructured_grid_has_poly_line_cells,
    a_contact_series_reads_step_by_step,
    cell_problems_read,
]:
    check(test.__name__, test)
status = "ok" if failed == 0 else "FAILED"
print(f"test result: {status}. {passed} passed; {failed} failed; VTK {vtk.vtkVersion.GetVTKVersion()}")
sys.exit(1 if failed else 0)
