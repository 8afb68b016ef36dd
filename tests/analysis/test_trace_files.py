"""Trace files as instruments write them: the delimiter detected, the user's own
column names mapped (with clear errors), the binary copy read only while it is fresh,
and the figure of the trace with its events, labelled in the trace's units."""
from __future__ import annotations

import os

import numpy as np
import pytest

from filmfriction.analysis.synthetic import klein_trace
from filmfriction.analysis.trace import (binary_copy_path, map_columns, read_trace,
                                         write_binary_copy)

NAMES = {"time": "t_s", "spring_force": "F_N", "drive_position": "x_m"}


@pytest.fixture(scope="module")
def columns():
    tr = klein_trace(cycles=3, dt=2e-3, noise=5e-8, seed=3)
    return {k: tr[k] for k in NAMES}


def _write(path, columns, sep, names=NAMES, decimal="."):
    lines = ["# an instrument's export", sep.join(names[k] for k in columns) if sep != " "
             else "  ".join(names[k] for k in columns)]
    for row in zip(*columns.values()):
        lines.append(sep.join(f"{v:.10g}".replace(".", decimal) for v in row))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("sep,name", [(",", "comma"), ("\t", "tab"), (";", "semicolon"),
                                      (" ", "whitespace")])
def test_every_delimiter_reads_the_same_numbers(tmp_path, columns, sep, name):
    path = _write(tmp_path / "trace.txt", columns, sep)
    mapping = {k: v for k, v in NAMES.items()}
    tr = read_trace(path, columns=mapping, units="si")
    assert tr.layout.delimiter == name
    assert tr.layout.columns == mapping
    for k, v in columns.items():
        np.testing.assert_allclose(tr.columns[k], v, rtol=1e-9, atol=0)


def test_decimal_commas_in_a_semicolon_table(tmp_path, columns):
    path = _write(tmp_path / "trace.csv", columns, ";", decimal=",")
    tr = read_trace(path, columns=NAMES)
    np.testing.assert_allclose(tr.columns["spring_force"], columns["spring_force"], rtol=1e-9)
    assert any("decimal commas" in n for n in tr.notes)


@pytest.mark.parametrize("sep", [",", ";", "\t"])
def test_a_byte_order_mark_is_not_part_of_the_first_name(tmp_path, columns, sep):
    # a spreadsheet's "CSV UTF-8" export starts with one
    path = _write(tmp_path / "trace.csv", columns, sep)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes().split(b"\n", 1)[1])
    tr = read_trace(path, columns=NAMES)
    np.testing.assert_allclose(tr.columns["time"], columns["time"], rtol=1e-9)


@pytest.mark.parametrize("data, says", [
    (b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03", "binary data"),       # gzip
    (b"\x93NUMPY\x01\x00v\x00{'descr': '<f8'}", "binary data"),           # .npy
    ("time\tF\n0\t1\n".encode("utf-16"), "UTF-16 text"),
])
def test_a_file_that_is_not_a_text_trace_says_what_it_is(tmp_path, data, says):
    path = tmp_path / "trace.csv"
    path.write_bytes(data)
    with pytest.raises(ValueError, match=says):
        read_trace(path)


def test_rows_that_do_not_match_the_header_say_so(tmp_path):
    path = tmp_path / "trace.csv"
    path.write_text("time,spring_force,gap\n0,1\n1,2\n")
    with pytest.raises(ValueError, match=r"the header has 3 comma-separated columns, the first "
                                         r"data row \(line 2\) 2"):
        read_trace(path)


def test_mapping_errors_name_what_exists():
    with pytest.raises(ValueError, match=r"unknown name 'force'.*spring_force"):
        map_columns(["t_s", "F_N"], {"time": "t_s", "force": "F_N"})
    with pytest.raises(ValueError, match=r"no column 'F' in the header \(columns: t_s, F_N\)"):
        map_columns(["t_s", "F_N"], {"time": "t_s", "spring_force": "F"})
    with pytest.raises(ValueError, match="would all be called 'time'"):
        map_columns(["t_s", "time"], {"time": "t_s"})


def test_an_unmapped_file_says_how_to_map(tmp_path, columns):
    path = _write(tmp_path / "trace.tsv", columns, "\t")
    with pytest.raises(ValueError, match=r"required column 'time' missing \(header: t_s, F_N, "
                                         r"x_m\); name it with --column time=NAME"):
        read_trace(path)


def test_the_binary_copy_is_read_only_while_fresh(tmp_path, columns):
    path = _write(tmp_path / "trace.tsv", columns, "\t")
    text = read_trace(path, columns=NAMES)
    assert not text.layout.binary
    copy = write_binary_copy(text)
    assert copy == binary_copy_path(path) == tmp_path / "trace.npy"
    binary = read_trace(path, columns=NAMES)
    assert binary.layout.binary
    for k in columns:
        np.testing.assert_array_equal(binary.columns[k], text.columns[k])
    # the text edited after the copy: the text is read again
    shorter = {k: v[:-10] for k, v in columns.items()}
    _write(path, shorter, "\t")
    st = copy.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    again = read_trace(path, columns=NAMES)
    assert not again.layout.binary and len(again) == len(columns["time"]) - 10


def test_a_foreign_npy_beside_the_text_is_ignored(tmp_path, columns):
    path = _write(tmp_path / "trace.tsv", columns, "\t")
    np.save(tmp_path / "trace.npy", np.zeros((5, 3)))
    tr = read_trace(path, columns=NAMES)
    assert not tr.layout.binary and len(tr) == len(columns["time"])


def test_figure_of_the_trace_is_labelled_in_its_units(tmp_path, columns):
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.trace_figure import trace_figure

    path = _write(tmp_path / "trace.tsv", columns, "\t")
    for units, force, time in (("si", "spring force [µN]", "time [s]"),
                               ("lj", "spring force [ε/σ]", "time [τ]")):
        tr = read_trace(path, columns=NAMES, units=units, spring_constant=97.0)
        _, per_cycle = analyze(tr, structure=False)
        fig = trace_figure(tr, per_cycle["yield_index"], per_cycle["stick_index"])
        force_ax, wall_ax = fig.axes
        assert force_ax.get_ylabel() == force and wall_ax.get_xlabel() == time
        # one marker per slip at y and at s, on the force curve
        markers = {line.get_label(): line for line in force_ax.get_lines()}
        n = len(per_cycle["yield_index"])
        assert n >= 2
        assert len(markers[f"yield y ({n})"].get_xdata()) == n
        assert len(markers[f"re-stick s ({n})"].get_xdata()) == n
