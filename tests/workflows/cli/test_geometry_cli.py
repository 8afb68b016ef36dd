"""``filmfriction geometry``: the data file film_slide.lmp starts from, for a run by hand."""
from filmfriction.md_inputs.contract import AtomType
from filmfriction.workflows.cli.main import main
from filmfriction.workflows.md.scenes.parameters import geometry, resolve


def test_writes_the_scene_geometry(tmp_path, capsys):
    out = tmp_path / "sub" / "walls.data"
    assert main(["geometry", "--set", "film_layers=4", "--set", "wall_model=flexible",
                 "--out", str(out)]) == 0
    expected = geometry(resolve({"film_layers": 4, "wall_model": "flexible"}))
    assert out.read_text() == expected.lammps_data()
    assert "film_layers=4" in out.read_text().splitlines()[0]
    printed = capsys.readouterr().out
    assert f"{expected.film.n_atoms} film atoms" in printed and "flexible" in printed
    atoms = out.read_text().split("Atoms # atomic")[1].split()
    assert {int(t) for t in atoms[1::5]} == set(map(int, AtomType))


def test_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "g.data"
    assert main(["geometry", "--set", "film_layers=40", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "film_layers" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
    assert main(["geometry", "--out", str(tmp_path)]) == 2     # a directory
    assert "is a directory" in capsys.readouterr().err
