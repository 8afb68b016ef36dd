"""filmfriction slip-law: runs pooled from their directories, and the inputs it refuses."""
import json

import pytest

from filmfriction.analysis.groundtruth.synthetic import run_directory
from filmfriction.workflows.cli.main import main


@pytest.fixture
def runs(tmp_path):
    return [run_directory(tmp_path / f"seed{i}", trajectory=False, seed=i) for i in range(3)]


def test_pooled_runs_printed_and_written(runs, tmp_path, capsys):
    out = tmp_path / "doc" / "pooled.json"
    assert main(["slip-law", *map(str, runs), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert text.startswith("pooled, jackknife over runs (3 runs, 2 dof):")
    assert "jackknife over slips (comparison) (9 slips, 8 dof)" in text
    doc = json.loads(out.read_text())
    assert doc["schema"] == "filmfriction.slip_law_pooled/1" and doc["slips"] == 9
    assert [r["slips"] for r in doc["runs"]] == [3, 3, 3]
    # the synthetic runs are Klein's viscous slips, B = 40 m/τ
    assert doc["pooled"]["damping"]["mean"] == pytest.approx(40.0, rel=0.05)
    assert doc["pooled"]["damping"]["units"] == "m/τ"


def test_runs_of_different_sliders_refused(runs, capsys):
    doc = json.loads((runs[2] / "run.json").read_text())
    doc["trace_parameters"]["mass"] = 250.0
    (runs[2] / "run.json").write_text(json.dumps(doc))
    assert main(["slip-law", *map(str, runs)]) == 2
    err = capsys.readouterr().err
    assert f"{runs[2]}: mass = 250.0" in err and "500.0" in err and "Traceback" not in err


def test_two_runs_refused(runs, capsys):
    assert main(["slip-law", *map(str, runs[:2])]) == 2
    assert "pooling needs 3 or more" in capsys.readouterr().err


def test_a_cycles_table_that_disagrees_with_its_analysis_is_refused(runs, capsys):
    from filmfriction.analysis.analyze import analyse_run

    analyse_run(runs[1])
    csv = runs[1] / "analysis_cycles.csv"
    csv.write_text(csv.read_text().splitlines()[0] + "\n")      # the header only
    assert main(["slip-law", *map(str, runs)]) == 2
    err = capsys.readouterr().err
    assert "analysis_cycles.csv holds 0 slip(s), analysis.json 4" in err, err
    assert "Traceback" not in err


def test_the_registry_fitted_where_recorded_and_left_out_on_request(runs, capsys):
    # runs that record their walls' registry period have a force periodic in the wall's
    # position fitted beside the law where their slips span two periods, and say so;
    # --no-registry fits the law alone; a period longer than half the slips is not fitted.
    # These synthetic slips (0.38 σ) carry no such force: every fit reads Klein's B = 40 m/τ
    def record(period):
        for r in runs:
            doc = json.loads((r / "run.json").read_text())
            doc["trace_parameters"]["registry_period"] = period
            (r / "run.json").write_text(json.dumps(doc))

    def pooled(*more):
        assert main(["slip-law", *map(str, runs), "--json", *more]) == 0
        return json.loads(capsys.readouterr().out)

    record(0.15)
    fitted, alone = pooled(), pooled("--no-registry")
    assert main(["slip-law", *map(str, runs)]) == 0
    assert "the walls' registry force" in capsys.readouterr().out
    record(1.1)
    short = pooled()
    assert fitted["shared"]["registry_period"] == 0.15
    assert alone["shared"]["registry_period"] is None and short["shared"]["registry_period"] is None
    for doc in (fitted, alone, short):
        assert doc["pooled"]["damping"]["mean"] == pytest.approx(40.0, rel=0.05)
    assert fitted["pooled"]["damping"]["stderr"] != alone["pooled"]["damping"]["stderr"]
    assert short["pooled"]["damping"] == alone["pooled"]["damping"]


def test_the_viscous_lag_recorded_and_a_bad_one_refused(runs, capsys):
    # the lag the slips were read with is recorded in the document and said; a lag that is
    # not a positive time is refused before any fit
    assert main(["slip-law", *map(str, runs), "--viscous-lag", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert main(["slip-law", *map(str, runs), "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert doc["shared"]["viscous_lag"] == 2.0 and plain["shared"]["viscous_lag"] is None
    # the fit took it: B's regressor is the lagged slide, which moves B
    assert doc["pooled"]["damping"]["mean"] != pytest.approx(plain["pooled"]["damping"]["mean"],
                                                             rel=1e-3)
    assert main(["slip-law", *map(str, runs), "--viscous-lag", "2"]) == 0
    assert "lagging the shear rate by 2 τ" in capsys.readouterr().out
    for bad in ("0", "-3", "nan"):
        assert main(["slip-law", *map(str, runs), "--viscous-lag", bad]) == 2
        err = capsys.readouterr().err
        assert f"--viscous-lag {float(bad)!r}" in err and "Traceback" not in err
