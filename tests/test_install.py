"""The installed project finds its engine and its data without any set-up by hand."""
import os
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_in_process_lammps_without_ld_library_path():
    # a fresh interpreter with no LD_LIBRARY_PATH: the libmpi.so.12 trap
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    code = ("from filmfriction.workflows.md.engine import lammps_module\n"
            "lmp = lammps_module().lammps(cmdargs=['-log', 'none', '-screen', 'none'])\n"
            "lmp.command('units lj')\n"
            "print(lmp.version())\n"
            "lmp.close()\n")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout.strip().splitlines()[-1]) >= 20250722


def test_lmp_child_finds_libmpi():
    from filmfriction.workflows.md import engine

    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    out = subprocess.run([str(engine.lmp_binary()), "-h"], env=engine.engine_env(env),
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert "Large-scale Atomic/Molecular Massively Parallel Simulator" in out.stdout


def test_wheel_ships_scripts_and_scenes(tmp_path):
    out = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
                          "-w", str(tmp_path), str(ROOT)], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    wheel = next(tmp_path.glob("filmfriction-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    for needed in ("md_inputs/film_slide.lmp", "md_inputs/bulk_lj.lmp",
                   "workflows/md/scenes/stick-slip.toml", "workflows/md/scenes/smooth-sliding.toml",
                   "workflows/cli/main.py", "analysis/stickslip.py", "reduced_model/units.py",
                   "reduced_model/laws/__init__.py", "reduced_model/laws/coulomb.py", "__init__.py",
                   "analysis/schemas/analysis.schema.json", "analysis/schemas/sfb.schema.json",
                   "analysis/observables/observable.py", "analysis/observables/slips_section.py",
                   "workflows/report/templates/report.html.j2", "workflows/report/templates/report.md.j2",
                   "workflows/report/templates/report.css", "workflows/report/templates/report.js"):
        assert f"filmfriction/{needed}" in names, needed
    # every sub-package of the checkout is in the wheel (pyproject.toml lists them by name)
    packages = {str(p.relative_to(ROOT)) for layer in ("md_inputs", "reduced_model", "analysis",
                                                       "workflows")
                for p in (ROOT / layer).rglob("__init__.py")}
    missing = sorted(p for p in packages if f"filmfriction/{p}" not in names)
    assert not missing, missing
    # one import name: nothing of ours at the top level of the wheel but filmfriction
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"filmfriction"}, tops
    assert not any(n.startswith("filmfriction/tests/") or n.startswith("filmfriction/benchmarks/")
                   for n in names)
