"""Every docstring example of filmfriction runs, and prints what it says it prints.

The modules are found by walking the package (``pkgutil.walk_packages``), so a new
module's examples are run without being listed here.  pytest's own
``--doctest-modules`` is not used: the repository root is the package, which
confuses its collection.  An example marked ``# doctest: +SKIP`` is not run (the
structure examples that read a run directory are).
"""
from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import filmfriction

#: Modules whose examples would start LAMMPS, with the reason they are skipped.
#: None today: the examples of the runner and the engine are prose, not doctests.
NEEDS_LAMMPS: dict[str, str] = {}

#: Modules whose every example is marked +SKIP (they read a real run directory).
SKIPPED_ONLY = {"filmfriction.analysis.structure.layering",
                "filmfriction.analysis.structure.hexatic"}

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _module_names() -> list[str]:
    broken = []
    names = [filmfriction.__name__]
    names += [m.name for m in pkgutil.walk_packages(filmfriction.__path__, "filmfriction.",
                                                    onerror=broken.append)]
    assert not broken, f"sub-packages that do not import: {broken}"
    return names


def _doctests(name: str) -> list[doctest.DocTest]:
    """The examples in the docstrings of module ``name`` (not of the names it imports)."""
    module = importlib.import_module(name)
    return sorted((t for t in doctest.DocTestFinder(exclude_empty=True).find(module)
                   if t.examples), key=lambda t: t.name)


MODULES = _module_names()
#: module -> number of examples, for the modules that have any
EXAMPLES = {name: n for name in MODULES
            if (n := sum(len(t.examples) for t in _doctests(name)))}


def test_the_walk_finds_every_layer():
    for layer in ("md_inputs", "reduced_model", "analysis", "workflows"):
        assert f"filmfriction.{layer}" in MODULES
    assert "filmfriction.reduced_model.laws" in MODULES and len(MODULES) > 30


def test_there_are_examples_to_run():
    """The walk would otherwise pass on nothing: the examples known today are found."""
    assert sum(EXAMPLES.values()) >= 60, EXAMPLES
    for name in ("filmfriction", "filmfriction.reduced_model", "filmfriction.reduced_model.laws",
                 "filmfriction.analysis.stickslip", "filmfriction.workflows.sweep.plan"):
        assert name in EXAMPLES, name


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_docstring_examples(name):
    if name in NEEDS_LAMMPS:
        pytest.skip(NEEDS_LAMMPS[name])
    report: list[str] = []
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    for test in _doctests(name):
        runner.run(test, out=report.append)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0 or name in SKIPPED_ONLY, f"{name}: no example was run"
    assert result.failed == 0, "".join(report)
