"""Reading traces, the analyze command and its analysis.json."""
import json
import warnings

import numpy as np
import pytest

from filmfriction.analysis.groundtruth.synthetic import klein_trace, smooth_trace, write_csv
from filmfriction.analysis.files.trace import MissingInput, TraceParameters
from filmfriction.analysis.files.trace_reader import read_trace

warnings.filterwarnings("ignore", category=DeprecationWarning)

SFB = ["--units", "si", "--spring-constant", "97", "--mass", "1.47e-3",
       "--area", "4e-10", "--thickness", "3.5e-9", "--drive-velocity", "1e-7"]


@pytest.fixture(scope="module")
def sfb_csv(tmp_path_factory):
    tr = klein_trace(cycles=5, noise=0.005 * 9.7e-6, seed=2)
    path = tmp_path_factory.mktemp("sfb") / "sfb.csv"
    write_csv(path, {k: tr[k] for k in ("time", "spring_force", "drive_position")})
    return path


def test_read_csv_and_missing_pieces(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("# comment\ntime, spring_force ,gap\n0,1,3\n1,2,3\n2,1.5,3\n")
    tr = read_trace(p, thickness=2.0)
    assert len(tr) == 3 and tr.has("gap") and tr.units == "lj"
    with pytest.raises(MissingInput, match="column 'wall_velocity'"):
        tr.column("wall_velocity")
    with pytest.raises(MissingInput, match="--spring-constant"):
        tr.parameters.require("spring_constant")
    p.write_text("time,force\n0,1\n")
    with pytest.raises(ValueError, match="'spring_force' missing"):
        read_trace(p)


def test_truncated_file(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("time,spring_force\n0,1\n1,2\n2,")          # cut mid-row
    tr = read_trace(p)
    assert len(tr) == 2 and "truncated" in tr.notes[0]
    p.write_text("time,spring_force\n0,1\n1\n2,3\n")          # damaged inside
    with pytest.raises(ValueError, match="line 3 has 1 comma-separated values, the header 2"):
        read_trace(p)
    p.write_text("time,spring_force\n")
    with pytest.raises(ValueError, match="no data rows"):
        read_trace(p)


def test_bad_parameters():
    with pytest.raises(ValueError, match="units"):
        TraceParameters(units="cgs")
    with pytest.raises(ValueError, match="positive"):
        TraceParameters(mass=-1.0)


def test_analyze_sfb_csv(sfb_csv, run_cli):
    r = run_cli("analyze", sfb_csv, "--json", *SFB)
    assert r.code == 0, r.err
    printed = r.json()
    doc = json.loads((sfb_csv.parent / "analysis.json").read_text())
    assert printed == doc
    assert doc["regime"] == "stick-slip" and doc["units"] == "si"
    assert doc["slips"]["count"] == 5
    for key in ("static_force", "backward_force", "slip_distance", "slip_duration", "period"):
        entry = doc["slips"][key]
        assert {"mean", "stderr", "units"} <= set(entry)
        assert entry["mean"] > 0 and 0 <= entry["stderr"] < 0.1 * entry["mean"], (key, entry)
    assert doc["slips"]["static_force"]["units"] == "N"
    assert doc["slips"]["static_force"]["mean"] == pytest.approx(9.7e-6, rel=0.01)
    e = doc["energy"]
    assert e["spring_released"]["units"] == "J"
    assert 0.9 < e["viscous_fraction"]["mean"] <= 1.0
    # what the film does not dissipate during the slip is left at the stick
    assert e["at_stick_fraction"]["mean"] == pytest.approx(1.0 - e["viscous_fraction"]["mean"],
                                                           abs=1e-12)
    eta = doc["viscosity"]["from_slip"]["eta_eff"]
    assert eta["units"] == "Pa·s"
    assert eta["mean"] == pytest.approx(3.09 * 3.5e-9 / 4e-10, rel=0.02)   # 27 Pa·s
    assert "viscosity.steady" in doc["skipped"]
    csv_rows = (sfb_csv.parent / doc["cycles_csv"]).read_text().splitlines()
    assert len(csv_rows) == 1 + 5 and "eta_eff" in csv_rows[0]


def test_analyze_without_parameters_skips_with_reasons(sfb_csv, tmp_path, run_cli):
    out = tmp_path / "a.json"
    assert run_cli("analyze", sfb_csv, "--units", "si", "--output", out).code == 0
    doc = json.loads(out.read_text())
    assert doc["slips"]["count"] == 5 and doc["slips"]["period"]["mean"] > 0
    assert "--spring-constant" in doc["skipped"]["energy"]
    assert "--spring-constant" in doc["skipped"]["viscosity.from_slip"]


def test_analyze_smooth_sliding_steady_viscosity(tmp_path, run_cli):
    tr = smooth_trace(mean_force=2.0, noise=0.05, rho=0.9, n=20000, velocity=0.01, gap=4.0)
    p = tmp_path / "smooth.csv"
    write_csv(p, tr)
    r = run_cli("analyze", p, "--json", "--area", "50", "--drive-velocity", "0.01")
    assert r.code == 0, r.err
    doc = r.json()
    assert doc["regime"] == "smooth" and doc["slips"]["count"] == 0
    st = doc["viscosity"]["steady"]
    assert st["eta_eff"]["units"] == "ετ/σ³"
    assert st["eta_eff"]["mean"] == pytest.approx(2.0 / 50 / (0.01 / 4.0), rel=0.02)
    assert st["thickness"]["source"].startswith("mean of gap column")   # no layer count: the gap


def test_user_errors(tmp_path, run_cli):
    missing = run_cli("analyze", tmp_path / "nope.csv")
    assert missing.code == 2 and "nope.csv" in missing.err
    p = tmp_path / "nan.csv"
    p.write_text("time,spring_force\n0,1\n1,nan\n2,1\n3,2\n")
    r = run_cli("analyze", p, "--json")
    # the row is dropped, said and recorded; never interpolated
    assert r.code == 0, r.err
    source = r.json()["source"]
    assert source["samples"] == 3
    assert source["dropped_rows"] == {"count": 1, "columns": {"spring_force": 1}, "lines": [3]}
    assert any("dropped 1 row with empty, NaN or infinite cells (line 3; spring_force 1)" in n
               for n in source["notes"])


def test_analyze_run_directory(synthetic_run, run_cli):
    run = synthetic_run
    r = run_cli("analyze", run, "--json")
    assert r.code == 0, r.err
    doc = r.json()
    assert json.loads((run / "analysis.json").read_text()) == doc
    assert doc["regime"] == "stick-slip" and doc["units"] == "lj"
    assert doc["slips"]["count"] == 4
    assert doc["energy"]["ledger"]["closure"]["mean"] < 0.02
    assert doc["viscosity"]["from_slip"]["eta_eff"]["units"] == "ετ/σ³"
    assert doc["structure"]["layers"]["count"] == 3
    assert doc["structure"]["stick"]["frames"] + doc["structure"]["slip"]["frames"] == 60


@pytest.mark.parametrize("case", ["stuck", "late-slip", "startup-then-sliding"])
def test_fewer_than_two_slips_is_smooth_only_when_the_wall_slides(tmp_path, run_cli, case):
    # K = 100, V = 0.02: a ramp of 2 eps/sigma per tau
    k, v = 100.0, 0.02
    t = np.arange(0.0, 100.0, 0.25)
    rng = np.random.default_rng(0)
    if case == "stuck":            # the force ramps up and never yields
        f = k * v * t
    elif case == "late-slip":      # sliding at 30, then at 80 tau a drop to 10 and a new
        # ramp: the wall still moves at V on average, only the slip's timing tells
        f = np.where(t < 80.0, 30.0, np.minimum(10.0 + k * v * (t - 80.0), 30.0))
    else:                          # a start-up yield at 20 tau, then steady sliding at 30
        f = np.where(t < 20.0, k * v * t, 30.0)
    f = f + 0.3 * rng.standard_normal(t.size)
    wall = v * t - f / k
    p = tmp_path / "trace.csv"
    write_csv(p, {"time": t, "spring_force": f, "wall_position": wall,
                  "drive_position": v * t})
    r = run_cli("analyze", p, "--json", "--spring-constant", k, "--drive-velocity", v)
    assert r.code == 0, r.err
    doc = r.json()
    want = "smooth" if case == "startup-then-sliding" else "unresolved"
    assert doc["regime"] == want, (doc["regime"], doc.get("regime_note"))
    if want == "unresolved":
        assert doc["regime_note"].startswith("fewer than 2 slips, but")


#: traces too short to classify: rows, the flags given, a run directory (else a CSV file)
SHORT = {
    "1 row": (1, [], False),
    "2 rows": (2, [], False),
    "9 rows, every parameter": (9, ["--spring-constant", "100", "--mass", "5", "--area", "50",
                                    "--thickness", "3", "--drive-velocity", "0.02"], False),
    "9 rows in a run directory": (9, [], True),
}


@pytest.mark.parametrize("case", list(SHORT))
def test_a_trace_too_short_to_classify_is_unresolved_with_its_reason(tmp_path, run_cli, case):
    from filmfriction.analysis.observables import registered
    from filmfriction.analysis.analyze import MIN_ROWS

    rows, flags, run_dir = SHORT[case]
    assert rows < MIN_ROWS
    t = np.arange(rows) * 0.5
    p = tmp_path / ("trace.csv" if run_dir else "short.csv")
    write_csv(p, {"time": t, "spring_force": 1.0 + 0.1 * t, "wall_position": 0.02 * t,
                  "wall_velocity": np.full(rows, 0.02)})
    r = run_cli("analyze", tmp_path if run_dir else p, "--json", *flags)
    assert r.code == 0, r.err
    doc = r.json()
    assert json.loads((tmp_path / "analysis.json").read_text()) == doc
    assert doc["regime"] == "unresolved"
    assert f"{rows} data row{'' if rows == 1 else 's'}: too short to classify" \
        in doc["regime_note"]
    # every section is listed as skipped with that reason, none is written (but the
    # trajectory sections of a CSV trace: it has no run directory, so no trajectory, no
    # place at all)
    keys = [o.key for o in registered()
            if run_dir or o.key not in ("structure", "shear_location")] + ["detection"]
    assert sorted(doc["skipped"]) == sorted(keys)
    assert all(why == doc["regime_note"] for why in doc["skipped"].values())
    assert not set(keys) & set(doc)
    # the per-slip CSV: no slips, no columns
    assert (tmp_path / doc["cycles_csv"]).read_text().strip() == ""


def test_a_short_trace_is_analysed_from_ten_rows(tmp_path, run_cli):
    from filmfriction.analysis.analyze import MIN_ROWS

    t = np.arange(MIN_ROWS) * 0.5
    p = tmp_path / "ten.csv"
    write_csv(p, {"time": t, "spring_force": np.ones(MIN_ROWS)})
    r = run_cli("analyze", p, "--json")
    assert r.code == 0, r.err
    doc = r.json()
    assert "too short" not in doc.get("regime_note", "") and doc["slips"]["count"] == 0


def test_thickness_is_layers_times_spacing_for_a_run(synthetic_run, run_cli):
    # a run records its film layers: D = gap n/(n+1) (Klein's D = n layers x spacing)
    import json as _json

    run = synthetic_run
    r = run_cli("analyze", run, "--json")
    assert r.code == 0, r.err
    doc = r.json()
    n = _json.loads((run / "run.json").read_text())["scene"]["parameters"]["film_layers"]
    th = doc["slip_law"]["eta_from_damping"] if "eta_from_damping" in doc.get("slip_law", {}) \
        else doc["viscosity"]["from_slip"]["thickness"]
    src = th["thickness_source"] if "thickness_source" in th else th["source"]
    d = th["thickness"] if "thickness_source" in th else th["mean"]
    assert f"n = {n}" in src
    import numpy as np
    gap = np.genfromtxt(run / "trace.csv", delimiter=",", names=True)["gap"].mean()
    assert d == pytest.approx(gap * n / (n + 1), rel=1e-6)
