#!/usr/bin/python3
"""Read lubkit output with a reader that is not lubkit's: meshio (Debian python3-meshio).

    meshio_check.py LABEL CASE [LABEL CASE ...]

For each case: the time series <case>/particles.xdmf through meshio's TimeSeriesReader, and
every time folder's particles.xdmf through meshio.read, against the HDF5 datasets read
directly with h5py and the times of the folders' uniform/state.yaml (the exact time lubFoam
wrote, as text).  Values are compared per particle id, bit for bit.  Prints PASS/FAIL lines.
"""
import os
import re
import sys

import h5py
import meshio
import numpy as np

failed = 0


def report(ok, what, detail=""):
    global failed
    if ok:
        print(f"PASS {what}")
    else:
        failed += 1
        print(f"FAIL {what}{': ' + detail if detail else ''}")


def folders(case):
    """Time folders holding particles.h5, by value."""
    out = []
    for name in os.listdir(case):
        try:
            v = float(name)
        except ValueError:
            continue
        if os.path.isfile(os.path.join(case, name, "particles.h5")):
            out.append((v, name))
    return [name for _, name in sorted(out)]


def exact_time(case, name):
    """uniform/state.yaml's time (lubFoam's folders); the file's own for 0/."""
    path = os.path.join(case, name, "uniform", "state.yaml")
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                m = re.match(r"time:\s*(\S+)", line)
                if m:
                    return float(m.group(1))
    with h5py.File(os.path.join(case, name, "particles.h5"), "r") as f:
        return float(f.attrs["time"])


def h5_fields(case, name):
    with h5py.File(os.path.join(case, name, "particles.h5"), "r") as f:
        return {k: f["fields"][k][()] for k in f["fields"]}


def by_id(ids, values):
    return {int(i): values[r] for r, i in enumerate(ids)}


def same_per_id(got_ids, got, want_ids, want):
    """got and want hold the same value for every id, and the same ids."""
    if sorted(map(int, got_ids)) != sorted(map(int, want_ids)):
        return False
    w = by_id(want_ids, want)
    return all(np.array_equal(np.asarray(v), np.asarray(w[int(i)])) for i, v in zip(got_ids, got))


def check_case(label, case):
    names = folders(case)
    try:
        reader = meshio.xdmf.TimeSeriesReader(os.path.join(case, "particles.xdmf"))
    except BaseException as e:  # meshio exits on some errors
        report(False, f"{label}: meshio TimeSeriesReader opens particles.xdmf", repr(e))
        return
    with reader:
        report(reader.num_steps == len(names),
               f"{label}: time series of {len(names)} times ({' '.join(names)})",
               f"meshio finds {reader.num_steps}")
        points, cells = reader.read_points_cells()
        first = h5_fields(case, names[0])
        report(np.array_equal(points, first["position"]) and len(cells) == 1
               and cells[0].type == "vertex" and len(cells[0].data) == len(points),
               f"{label}: geometry = the first time's positions, one vertex cell per particle")
        kind0 = by_id(first["id"], first["kind"])
        bad_t, bad_v, bad_kind, bad_rows, moved, shifted = [], [], 0, [], 0, []
        for k, name in enumerate(names[:reader.num_steps]):
            t, pd, _ = reader.read_data(k)
            if t != exact_time(case, name):
                bad_t.append(f"{name}: {t!r} vs {exact_time(case, name)!r}")
            want = h5_fields(case, name)
            for field, v in want.items():
                if field not in pd or not same_per_id(pd["id"], pd[field], want["id"], v):
                    bad_v.append(f"{name}/{field}")
            # the rows are the particles in id order, the same rows as the first time's
            # wherever a particle is in both: the first time's geometry then belongs to
            # the same particle as each time's data
            ids = pd["id"].astype(np.int64)  # meshio returns the file's uint64
            if np.any(ids[1:] <= ids[:-1]):
                bad_rows.append(name)
            # where the set is the first time's, row r is the same particle at both times
            # (the particle whose position the geometry gives in row r)
            if sorted(ids) == sorted(map(int, first["id"])) and not np.array_equal(ids, first["id"]):
                shifted.append(name)
            for i, kd in zip(ids, pd["kind"]):
                if int(i) in kind0 and kind0[int(i)] != kd:
                    bad_kind += 1
            pos = pd.get("position")
            moved += int(pos is not None and (pos.shape != points.shape or np.any(pos != points)))
        report(not bad_t, f"{label}: each time's Time Value is the exact time of its folder",
               "; ".join(bad_t[:3]))
        report(not bad_v, f"{label}: every field of every time equal per id to the HDF5 data",
               " ".join(bad_v[:5]))
        report(not bad_rows, f"{label}: rows in id order at every time", " ".join(bad_rows))
        report(not shifted, f"{label}: the geometry's rows are the same particles as every "
               "time's data rows (where the set is the same)", " ".join(shifted))
        report(bad_kind == 0, f"{label}: kind per id the same at every time",
               f"{bad_kind} rows differ")
        report(len(names) < 2 or moved > 0,
               f"{label}: the 'position' attribute gives each time's positions (moved at {moved} times)")
    bad = []
    for name in names:
        try:
            m = meshio.read(os.path.join(case, name, "particles.xdmf"))
        except BaseException as e:
            bad.append(f"{name}: {e!r}")
            continue
        want = h5_fields(case, name)
        if not np.array_equal(m.points, want["position"]):
            bad.append(f"{name}: points")
        for field, v in want.items():
            if field not in m.point_data or not np.array_equal(m.point_data[field], v):
                bad.append(f"{name}/{field}")
    report(not bad, f"{label}: meshio.read reads every folder's particles.xdmf", "; ".join(bad[:3]))


args = sys.argv[1:]
for j in range(0, len(args) - 1, 2):
    check_case(args[j], args[j + 1])
sys.exit(1 if failed else 0)
