"""The film's state during slips grouped by slider mass (benchmarks/slip_law/slip_film_state.py),
on run directories of known heating and dilation."""
import json

import numpy as np
import pytest


def _run(path, mass, rise, dilation, shear=None):
    # a trace of 0.25 τ samples: the film at kT 0.6 and gap 6.6 σ, raised by ``rise`` and
    # ``dilation`` inside each of three slips (samples 100–140, 300–360, 500–520)
    path.mkdir()
    t = np.arange(700) * 0.25
    temperature, gap = np.full(t.size, 0.6), np.full(t.size, 6.6)
    slips = ((100, 140), (300, 360), (500, 520))
    for i, j in slips:
        temperature[i:j + 1] += rise
        gap[i:j + 1] += dilation
    np.savetxt(path / "trace.csv", np.column_stack([t, temperature, gap]), delimiter=",",
               header="time,film_temperature,gap", comments="")
    np.savetxt(path / "analysis_cycles.csv", np.array(slips), delimiter=",", fmt="%d",
               header="yield_index,stick_index", comments="")
    (path / "analysis.json").write_text(json.dumps(
        {"source": {"parameters": {"mass": mass}},
         **({"shear_location": shear} if shear else {})}))
    return str(path)


def test_the_slips_heating_dilation_and_shear_planes_by_mass(benchmark_module, capsys,
                                                              tmp_path):
    main = benchmark_module("slip_law/slip_film_state").main
    shear = {"jump": [0.0, 0.5, 0.5, 0.0], "location": "spread"}
    runs = [_run(tmp_path / "a", 1000.0, 0.02, 0.05, shear),
            _run(tmp_path / "b", 1000.0, 0.04, 0.03, shear),
            _run(tmp_path / "c", 3000.0, 0.01, 0.0)]
    assert main(runs) == 0
    rows = {r.split("|")[1].strip(): [c.strip() for c in r.split("|")[2:-1]]
            for r in capsys.readouterr().out.splitlines()[2:]}
    assert rows["1000"][:2] == ["2", "6"] and rows["3000"][:2] == ["1", "3"]
    rise, dilation = (float(rows["1000"][k].split(" ± ")[0]) for k in (2, 3))
    assert rise == pytest.approx(0.03) and dilation == pytest.approx(0.04)
    assert float(rows["3000"][2].split(" ± ")[0]) == pytest.approx(0.01)
    assert rows["1000"][4] == "10"                      # slips of 10, 15, 5 τ in each run
    assert rows["1000"][5] == "0.00, 0.50, 0.50, 0.00" and rows["1000"][6] == "spread 2"
    assert rows["3000"][5] == "–" and rows["3000"][6] == "none 1"


def test_the_film_state_benchmark_refuses_runs_not_analysed(benchmark_module, capsys,
                                                            tmp_path):
    main = benchmark_module("slip_law/slip_film_state").main
    assert main([str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "not analysed" in err and str(tmp_path) in err
    with pytest.raises(SystemExit):
        main([str(tmp_path), "--before", "0"])
    assert "--before 0.0" in capsys.readouterr().err


def test_the_film_state_benchmark_says_which_run_it_cannot_read(benchmark_module, capsys,
                                                                tmp_path):
    main = benchmark_module("slip_law/slip_film_state").main
    run = _run(tmp_path / "a", 1000.0, 0.02, 0.05)
    (tmp_path / "a" / "analysis.json").write_text("{}")          # no slider's mass
    assert main([run]) == 1
    err = capsys.readouterr().err
    assert "slip_film_state:" in err and "Traceback" not in err and run in err
