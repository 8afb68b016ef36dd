"""Trace files as instruments and LAMMPS write them: the delimiter detected, the user's
own column names mapped (with clear errors) and their units converted and checked against
K and V, LAMMPS's fix print / fix ave/time files and logs (real files of a small run,
tests/analysis/data/lammps), metadata lines skipped, rows with missing values dropped and
said, the binary copy read only while it is fresh, and the figure of the trace with its
events, labelled in the trace's units."""
from __future__ import annotations

import os

import numpy as np
import pytest

from filmfriction.analysis.groundtruth.synthetic import klein_trace
from filmfriction.analysis.files.trace_reader import map_columns, read_trace
from filmfriction.analysis.files.trace_cache import binary_copy_path, write_binary_copy

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


def test_the_binary_copy_is_read_only_while_fresh(tmp_path, columns, monkeypatch):
    import filmfriction.analysis.files.trace_cache as trace_mod

    monkeypatch.setattr(trace_mod, "CACHE_MIN_BYTES", 0)      # this short file too
    path = _write(tmp_path / "trace.tsv", columns, "\t")
    text = read_trace(path, columns=NAMES)
    assert not text.layout.binary
    copy = write_binary_copy(text)
    assert copy == binary_copy_path(path)
    assert copy.parent == tmp_path / trace_mod.CACHE_DIR and copy.name.startswith("trace.tsv.")
    assert not (tmp_path / "trace.npy").exists()
    binary = read_trace(path, columns=NAMES)
    assert binary.layout.binary
    for k in columns:
        np.testing.assert_array_equal(binary.columns[k], text.columns[k])
    # the text edited after the copy, and dated before it: the text is read again
    shorter = {k: v[:-10] for k, v in columns.items()}
    _write(path, shorter, "\t")
    st = copy.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns - 10**9))
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


# ---------------------------------------------------------------------------- units
SI_NAMES = {"time": "t", "spring_force": "F", "drive_position": "x"}
#: the example SFB set-up's K and V (docs/examples/my_sfb.toml), those of klein_trace
K, V = 97.0, 1.0e-7


def _scaled(tmp_path, columns, scale, name="trace.tsv", names=SI_NAMES):
    """The trace written with each column multiplied by ``scale[name]`` (its numbers in
    another unit)."""
    scaled = {k: v * scale.get(k, 1.0) for k, v in columns.items()}
    return _write(tmp_path / name, scaled, "\t", names=names)


def test_columns_in_their_own_units_give_the_si_analysis(tmp_path, columns):
    from filmfriction.analysis.analyze import analyze

    si = read_trace(_scaled(tmp_path, columns, {}, "si.tsv"), columns=SI_NAMES, units="si",
                    spring_constant=K, drive_velocity=V)
    other = _scaled(tmp_path, columns, {"time": 1e3, "spring_force": 1e6,
                                        "drive_position": 1e9}, "other.tsv")
    tr = read_trace(other, columns=SI_NAMES, units="si", spring_constant=K, drive_velocity=V,
                    column_units={"time": "ms", "spring_force": "uN", "drive_position": "nm"})
    assert tr.layout.column_units == {"time": "ms", "spring_force": "uN", "drive_position": "nm"}
    assert "spring_force read in uN: x 1e-06 to N" in tr.notes
    for k in columns:
        np.testing.assert_allclose(tr.columns[k], si.columns[k], rtol=1e-9)
    doc_si, _ = analyze(si, structure=False)
    doc, _ = analyze(tr, structure=False)
    for name in ("static_force", "slip_distance", "slip_duration", "period"):
        assert doc["slips"][name]["mean"] == pytest.approx(doc_si["slips"][name]["mean"],
                                                           rel=1e-9)
    assert doc["units_check"]["stick_ramp"]["agrees"] and not doc["units_check"]["warnings"]
    assert 0.95 < doc["units_check"]["stick_ramp"]["ratio"] < 1.05


@pytest.mark.parametrize("scale, says", [
    # µN, nm and ms read as N, m and s: ramps 1e3 x K V, drive 1e6 x V
    ({"time": 1e3, "spring_force": 1e6, "drive_position": 1e9},
     "the stick ramps rise at 1e3 × K·V"),
    # only the time in ms: ramps 1e-3 x K V, the drive too
    ({"time": 1e3}, "the stick ramps rise at 1e-3 × K·V"),
    # the force in µN
    ({"spring_force": 1e6}, "the stick ramps rise at 1e6 × K·V"),
])
def test_a_column_read_in_the_wrong_unit_is_named(tmp_path, columns, scale, says):
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.observables.units_check_section import likely_units

    path = _scaled(tmp_path, columns, scale)
    tr = read_trace(path, columns=SI_NAMES, units="si", spring_constant=K, drive_velocity=V)
    doc, _ = analyze(tr, structure=False)
    check = doc["units_check"]
    assert not check["stick_ramp"]["agrees"]
    (warning,) = check["warnings"]
    assert says in warning
    # the true units are among those the warning names
    truth = {"time": {1e3: "ms"}, "spring_force": {1e6: "uN"}, "drive_position": {1e9: "nm"}}
    wanted = {k: truth[k][v] for k, v in scale.items()}
    ratios = {"stick_ramp": check["stick_ramp"]["ratio"], "drive": check["drive"]["ratio"]}
    guesses = likely_units(ratios, {"spring_force": "N", "time": "s", "drive_position": "m"},
                           {"stick_ramp": (0.1, 3.0), "drive": (0.9, 1.1)})
    assert wanted in guesses, guesses
    assert " and ".join(f"{k} ({SI_NAMES[k]}) in {u}" for k, u in wanted.items()).split(" and ")[0] \
        in warning


def test_a_column_named_like_a_unit_but_read_in_another_is_said(tmp_path, columns):
    from filmfriction.analysis.analyze import analyze

    names = {"time": "t_ms", "spring_force": "F_N", "drive_position": "x_m"}
    path = _scaled(tmp_path, columns, {"time": 1e3}, names=names)
    tr = read_trace(path, columns=names, units="si", spring_constant=K, drive_velocity=V)
    doc, _ = analyze(tr, structure=False)
    hints = doc["units_check"]["name_hints"]
    assert hints == [{"column": "time", "file_column": "t_ms", "named": "ms", "read_in": "s"}]
    assert any("give --column time=t_ms:ms" in w for w in doc["units_check"]["warnings"])


def test_an_md_trace_in_lj_units_passes_the_check(synthetic_run):
    from filmfriction.analysis.analyze import analyze

    doc, _ = analyze(read_trace(synthetic_run), structure=False)
    check = doc["units_check"]
    assert check["stick_ramp"]["agrees"] and not check["warnings"], check


def test_lj_units_and_cross_system_conversion(tmp_path, columns):
    from filmfriction.reduced_model.units import OMCTS

    path = _scaled(tmp_path, columns, {})
    lj = read_trace(path, columns=SI_NAMES, units="lj",
                    column_units={"time": "s", "spring_force": "N", "drive_position": "m"})
    np.testing.assert_allclose(lj.time, columns["time"] / OMCTS.tau, rtol=1e-9)
    np.testing.assert_allclose(lj.spring_force, columns["spring_force"] / OMCTS.force,
                               rtol=1e-9)
    assert any("with the OMCTS mapping" in n for n in lj.notes)
    tr = read_trace(path, columns=SI_NAMES, units="lj", column_units={"time": "tau"})
    np.testing.assert_allclose(tr.time, columns["time"], rtol=1e-9)


# ---------------------------------------------------------------------------- LAMMPS files
LAMMPS = __import__("pathlib").Path(__file__).resolve().parents[1] / "data" / "lammps"


def test_lammps_fix_print_file_reads_as_its_trace_csv():
    """The scene's trace.dat (a real run's, tests/analysis/data/lammps): the header is
    LAMMPS's comment title, repeated at the restart segment, whose first step is printed
    twice; the columns are trace.csv's, number for number."""
    csv = read_trace(LAMMPS / "trace.csv")
    dat = read_trace(LAMMPS / "trace.dat")
    assert len(dat) == len(csv) == 41
    for name in csv.columns:
        np.testing.assert_array_equal(dat.columns[name], csv.columns[name], err_msg=name)
    assert "skipped 1 comment line among the data rows" in dat.notes
    assert any("1 row repeating the next row's step" in n for n in dat.notes)


def test_lammps_log_thermo_runs():
    csv = read_trace(LAMMPS / "trace.csv")
    log = read_trace(LAMMPS / "log.lammps", log_run="2-3")
    assert log.layout.kind == "lammps-log" and log.layout.log_run == "2-3"
    # the slide's thermo keywords are the contract's columns (v_fs -> spring_force ...)
    for name in ("step", "time", "spring_force", "wall_position", "gap"):
        np.testing.assert_array_equal(log.columns[name], csv.columns[name], err_msg=name)
    one = read_trace(LAMMPS / "log.lammps", log_run="3")
    assert one.time[0] == pytest.approx(5.0) and len(one) == 21
    assert len(read_trace(LAMMPS / "log.lammps", log_run="2-")) == len(log)
    with pytest.raises(ValueError, match=r"holds 3 thermo runs \(1: steps 0-200, Step Time.*"
                                         r"runs with a time and a spring force: 2, 3; e.g. "
                                         r"--log-run 2-3\)"):
        read_trace(LAMMPS / "log.lammps")
    with pytest.raises(ValueError, match="required column 'spring_force' missing"):
        read_trace(LAMMPS / "log.lammps", log_run="1")
    with pytest.raises(ValueError, match="run 2's thermo keywords .* differ from run 1's"):
        read_trace(LAMMPS / "log.lammps", log_run="1-2")
    with pytest.raises(ValueError, match=r"--log-run 4: .* holds 3 finished thermo runs"):
        read_trace(LAMMPS / "log.lammps", log_run="4")


def test_a_log_with_an_unfinished_run_and_nan_rows_says_so(tmp_path):
    lines = (LAMMPS / "log.lammps").read_text().splitlines(keepends=True)
    header = [i for i, line in enumerate(lines) if line.lstrip().startswith("Step ")]
    # a NaN in the third slide row of run 2, and run 3 cut before its Loop time line
    row = header[1] + 3
    fields = lines[row].split()
    fields[-1] = "nan"
    lines[row] = " ".join(fields) + "\n"
    cut = header[2] + 5
    path = tmp_path / "log.lammps"
    path.write_text("".join(lines[:cut]))
    tr = read_trace(path, log_run="2")
    assert any(f"line {row + 1}" in n and "NaN" in n for n in tr.notes)
    assert tr.layout.dropped == {"count": 1, "lines": [row + 1]}
    assert any("did not finish" in n for n in tr.notes)
    assert len(tr) == 20


def test_lammps_fix_ave_time_file():
    tr = read_trace(LAMMPS / "ave_time.dat", columns={"time": "v_t", "spring_force": "v_pe"})
    assert len(tr) == 21 and tr.time[1] == pytest.approx(0.05)
    assert set(tr.columns) == {"TimeStep", "time", "spring_force", "c_thermo_temp"}


# ---------------------------------------------------------------------------- instrument files
def test_metadata_lines_are_skipped_by_count_or_prefix(tmp_path, columns):
    body = _write(tmp_path / "plain.tsv", columns, "\t").read_text().split("\n", 1)[1]
    meta = "Instrument: SFB-3\nOperator: A. B.\nDate: 2007-02-02\n"
    path = tmp_path / "instrument.tsv"
    path.write_text(meta + body)
    with pytest.raises(ValueError, match="skip them with --skip-rows N"):
        read_trace(path, columns=NAMES)
    tr = read_trace(path, columns=NAMES, skip_rows=3)
    np.testing.assert_allclose(tr.spring_force, columns["spring_force"], rtol=1e-9)
    assert tr.layout.skip_rows == 3
    path.write_text("".join(f"% {line}\n" for line in meta.splitlines()) + body)
    tr = read_trace(path, columns=NAMES, comments=("%",))
    assert len(tr) == len(columns["time"])
    with pytest.raises(ValueError, match=r"--skip-rows 9999: .* has \d+ lines"):
        read_trace(path, columns=NAMES, skip_rows=9999)


def test_empty_and_nan_cells_are_dropped_and_said_never_interpolated(tmp_path, columns):
    path = _write(tmp_path / "trace.csv", columns, ",")
    lines = path.read_text().splitlines()
    # line numbers in the file (1: comment, 2: header): an empty force, a NaN time,
    # an empty drive cell
    lines[9] = lines[9].rsplit(",", 2)[0] + ",," + lines[9].rsplit(",", 1)[1]
    lines[19] = "nan," + lines[19].split(",", 1)[1]
    lines[29] = lines[29].rsplit(",", 1)[0] + ","
    path.write_text("\n".join(lines) + "\n")
    tr = read_trace(path, columns=NAMES)
    n = len(columns["time"])
    assert len(tr) == n - 3
    assert tr.layout.dropped == {"count": 3, "lines": [10, 20, 30],
                                 "columns": {"time": 1, "spring_force": 1, "drive_position": 1}}
    note = next(n for n in tr.notes if n.startswith("dropped 3 rows"))
    assert "lines 10, 20, 30" in note and "not interpolated" in note
    # the rows kept are the file's own: nothing was filled in
    kept = np.delete(columns["time"], [7, 17, 27])
    np.testing.assert_allclose(tr.time, kept, rtol=1e-9)
    assert not np.isin(columns["time"][[7, 17, 27]], tr.time).any()


def test_a_cell_that_is_not_a_number_is_an_error_naming_its_line(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("time,spring_force\n0,1\n1,n/a\n2,3\n")
    with pytest.raises(ValueError, match=r"line 3, column spring_force: 'n/a' is not a number"):
        read_trace(path)
    path.write_text("time,spring_force\nnan,1\n,2\n")
    with pytest.raises(ValueError, match="no data rows left"):
        read_trace(path)


def test_a_run_gives_its_film_mass_and_an_older_run_its_film_atoms(synthetic_run):
    # the film's mass (the most a co-moving mass can be: the slip law's rule) is a trace
    # parameter; a run recorded before it was one gives its film atoms, 1 m each, and a run
    # without either gives none (the rule then does without)
    import json

    assert read_trace(synthetic_run).parameters.film_mass is None
    path = synthetic_run / "run.json"
    run = json.loads(path.read_text())
    path.write_text(json.dumps(run | {"atoms": {"film": 336, "top_wall": 180, "total": 696}}))
    assert read_trace(synthetic_run).parameters.film_mass == 336.0
    run["trace_parameters"]["film_mass"] = 224.0
    path.write_text(json.dumps(run | {"atoms": {"film": 336}}))
    assert read_trace(synthetic_run).parameters.film_mass == 224.0
    run["trace_parameters"]["film_mass"] = -1.0
    path.write_text(json.dumps(run))
    with pytest.raises(ValueError, match="film_mass"):
        read_trace(synthetic_run)


def test_a_run_gives_its_registry_period_and_an_older_run_its_walls_spacing(synthetic_run):
    # the walls' registry period (the slip law fits a force periodic in the wall's position
    # where it is known) is a trace parameter; a run recorded before it was one gives its
    # scene's wall spacing when its walls are aligned, none when twisted; a recorded None
    # stays None
    import json

    path = synthetic_run / "run.json"
    run = json.loads(path.read_text())
    assert read_trace(synthetic_run).parameters.registry_period is None
    scene = {**run.get("scene", {}), "name": "stick-slip",
             "parameters": {"wall_spacing": 1.1, "top_wall_twist": "aligned"}}
    path.write_text(json.dumps(run | {"scene": scene}))
    assert read_trace(synthetic_run).parameters.registry_period == 1.1
    scene["parameters"]["top_wall_twist"] = "twisted"
    path.write_text(json.dumps(run | {"scene": scene}))
    assert read_trace(synthetic_run).parameters.registry_period is None
    scene["parameters"]["top_wall_twist"] = "aligned"
    run["trace_parameters"]["registry_period"] = None
    path.write_text(json.dumps(run | {"scene": scene}))
    assert read_trace(synthetic_run).parameters.registry_period is None
    run["trace_parameters"]["registry_period"] = 0.0
    path.write_text(json.dumps(run))
    with pytest.raises(ValueError, match="registry_period"):
        read_trace(synthetic_run)
