"""The wall models beyond commensurate walls: a twisted top wall and walls with vacancies.

Each model is checked on its geometry (what the data file holds) and in a real,
small LAMMPS run (the script reads the file, and refuses one built for other
parameters).  Flexible walls have their own tests (test_walls.py).
"""
import json
import math
import subprocess

import numpy as np
import pytest

from filmfriction import md_inputs
from filmfriction.md_inputs.contract import DATA_FILE
from filmfriction.workflows.md import engine
from filmfriction.workflows.md.scene import Scene, SceneError, load
from filmfriction.workflows.md.scenes.parameters import parse_assignment, resolve

SMALL_BOX = {"cells_x": 5, "cells_y": 3}


def _surface(positions, top: bool):
    """The in-plane positions of the wall plane facing the film (all atoms of a
    plane share one z)."""
    z = np.round(positions[:, 2], 6)
    level = z.max() if top else z.min()
    return positions[z == level, :2]


def _row_angles(xy, box):
    """Directions (degrees, modulo 60) of the bonds from each atom to its nearest
    neighbours in a close-packed plane, with periodic images in x and y."""
    d = xy[None, :, :] - xy[:, None, :]
    d -= np.round(d / box) * box
    r = np.hypot(d[..., 0], d[..., 1])
    np.fill_diagonal(r, np.inf)
    near = r < 1.2 * r.min()
    return np.degrees(np.arctan2(d[..., 1][near], d[..., 0][near])) % 60.0


def _walls(p):
    """The bottom wall's and the top wall's atoms (ase.Atoms) of resolved parameters."""
    from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, TOP_WALL_TYPES

    atoms = Scene(name="w", description="", models="", outputs=(), expected_cost="",
                  parameters=p).geometry().atoms()
    types = atoms.numbers
    return (atoms[np.isin(types, [int(t) for t in BOTTOM_WALL_TYPES])],
            atoms[np.isin(types, [int(t) for t in TOP_WALL_TYPES])])


def test_the_new_wall_parameters_are_checked():
    assert parse_assignment("top_wall_twist=twisted") == ("top_wall_twist", "twisted")
    for text in ("top_wall_twist=30", "top_wall_twist=twisted; shell ls"):
        with pytest.raises(SceneError, match="must be one of aligned, twisted"):
            parse_assignment(text)
    with pytest.raises(SceneError, match=r"wall_vacancies = 0.6: outside the allowed range"):
        load("stick-slip", {"wall_vacancies": 0.6})
    with pytest.raises(SceneError, match="not a number"):
        parse_assignment("wall_vacancies=0.1; shell ls")
    v = load("stick-slip", {"top_wall_twist": "twisted", "wall_vacancies": 0.25}
             ).lammps_variables()
    assert v["top_wall_twist"] == "1" and v["wall_vacancies"] == "0.25"


def test_a_twisted_top_wall_has_its_rows_30_degrees_off_the_bottom_walls():
    box = None
    for twist, expected in (("aligned", 0.0), ("twisted", 30.0)):
        p = resolve({**SMALL_BOX, "top_wall_twist": twist})
        bottom, top = _walls(p)
        box = np.diag(bottom.cell)[:2]
        bottom_angles = _row_angles(_surface(bottom.positions, top=False), box)
        top_angles = _row_angles(_surface(top.positions, top=False), box)
        # 0 and 60 are one direction: fold onto the distance from 0
        fold = lambda a: np.minimum(a, 60.0 - a)  # noqa: E731
        np.testing.assert_allclose(fold(bottom_angles), 0.0, atol=1e-6)
        # the turned lattice is stretched to the box (here by about 4 %), which
        # tilts some bonds by about a degree
        assert np.abs(fold(top_angles) - expected).max() < 2.5, twist
    # a box the turned wall cannot fit is refused before LAMMPS
    with pytest.raises(SceneError, match="top_wall_twist = 'twisted' does not fit the box"):
        resolve({"cells_x": 6, "cells_y": 3, "top_wall_twist": "twisted"})


def test_the_registry_period_is_the_aligned_walls_lattice_along_the_slide():
    # the slip law fits a force periodic in the wall's position with the geometry's
    # registry_period: aligned, both walls' facing planes map onto themselves shifted by it
    # along x (and not by half of it); twisted, the top wall's rows are not the bottom's: none
    from filmfriction.workflows.md.scenes.parameters import geometry

    p = resolve(SMALL_BOX)
    period = geometry(p).registry_period
    assert period == p["wall_spacing"]
    bottom, top = _walls(p)
    box = np.diag(bottom.cell)[:2]

    def maps(points, shift):
        moved = (points + [shift, 0.0]) % box
        d = np.abs(moved[:, None, :] - points[None, :, :] % box)
        d = np.minimum(d, box - d)
        return bool(np.all(np.min(np.hypot(d[..., 0], d[..., 1]), axis=1) < 1e-6))

    for wall, facing_up in ((bottom, True), (top, False)):
        plane = _surface(wall.positions, top=facing_up)
        assert maps(plane, period) and not maps(plane, period / 2)
    assert geometry(resolve({**SMALL_BOX, "top_wall_twist": "twisted"})).registry_period is None


def test_vacancies_are_taken_from_the_planes_facing_the_film():
    full = resolve(SMALL_BOX)
    plane = 2 * 5 * 3
    b0, t0 = _walls(full)
    for fraction, seed in ((0.2, 1), (0.2, 2), (0.5, 1)):
        p = resolve({**SMALL_BOX, "wall_vacancies": fraction, "seed": seed})
        b, t = _walls(p)
        missing = math.floor(fraction * plane + 0.5)
        assert len(b) == len(b0) - missing and len(t) == len(t0) - missing
        # only the surface planes lose atoms
        assert len(_surface(b.positions, top=True)) == plane - missing
        assert len(_surface(t.positions, top=False)) == plane - missing
        assert len(_surface(b.positions, top=False)) == plane
    # the seed draws the sites
    s1 = _surface(_walls(resolve({**SMALL_BOX, "wall_vacancies": 0.2, "seed": 1}))[0].positions, True)
    s2 = _surface(_walls(resolve({**SMALL_BOX, "wall_vacancies": 0.2, "seed": 2}))[0].positions, True)
    again = _surface(_walls(resolve({**SMALL_BOX, "wall_vacancies": 0.2, "seed": 1}))[0].positions,
                     True)
    np.testing.assert_array_equal(s1, again)
    assert not np.array_equal(np.sort(s1, axis=0), np.sort(s2, axis=0))


@pytest.mark.md
@pytest.mark.parametrize("sets", [{"top_wall_twist": "twisted"}, {"wall_vacancies": 0.2},
                                  {"wall_model": "flexible", "wall_mass": 500.0,
                                   "thermostat_placement": "both", "wall_vacancies": 0.2,
                                   "top_wall_twist": "twisted"}])
def test_lammps_runs_each_wall_model_from_its_data_file(md, tmp_path, sets):
    scene = md.scene("stick-slip", film_layers=2, equilibrate_steps=500, slide_steps=1000,
                     trace_every=20, restart_every=0, **sets)
    run_dir = md.execute(scene, tmp_path / "run")
    record = json.loads((run_dir / "run.json").read_text())
    assert record["status"] == "completed"
    g = scene.geometry()
    # LAMMPS counted the atoms of the data file: the vacancies are missing from both walls
    vacant = sum(g.vacancies_per_wall)
    assert vacant == (12 if scene.parameters["wall_vacancies"] else 0)
    assert record["atoms"]["total"] == (g.bottom.n_atoms + g.film.n_atoms + g.top.n_atoms
                                        - vacant)
    assert record["atoms"]["top_wall"] == g.top.n_atoms - g.vacancies_per_wall[1]
    # the film stays held between the walls at its temperature
    d = md.trace(run_dir)
    assert abs(d["film_temperature"][len(d) // 2:].mean() - 0.7) < 0.1
    assert np.ptp(d["gap"]) < 0.5


@pytest.mark.md
def test_the_script_refuses_a_data_file_of_another_vacancy_fraction(tmp_path):
    p = resolve({**SMALL_BOX, "wall_vacancies": 0.2})
    scene = Scene(name="v", description="", models="", outputs=(), expected_cost="",
                  parameters=p)
    other = Scene(name="v", description="", models="", outputs=(), expected_cost="",
                  parameters=resolve({**SMALL_BOX, "wall_vacancies": 0.1}))
    (tmp_path / DATA_FILE).write_text(other.geometry().lammps_data())
    variables = {**scene.lammps_variables(), "equilibrate_steps": "0", "slide_steps": "0"}
    cmd = engine.lmp_command(1, md_inputs.script("film_slide.lmp"), variables)
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode != 0
    assert "has 27 atoms in the surface plane of the bottom wall, not the 30 sites less " \
           "wall_vacancies 0.2" in out.stdout
    # the data file of these parameters is accepted
    (tmp_path / DATA_FILE).write_text(scene.geometry().lammps_data())
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stdout[-2000:]
