"""Fixtures of the analysis tests."""
import functools
import importlib.util
from pathlib import Path

import pytest


@functools.cache
def _benchmark(name: str):
    path = Path(__file__).resolve().parents[2] / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def benchmark_module():
    """``benchmark_module("wall_load")``: the module of ``benchmarks/wall_load.py`` (the
    benchmarks are scripts, not a package), loaded once."""
    return _benchmark


@pytest.fixture
def slip_table():
    """``slip_table(trace, spring_constant, refine=True)`` -> (CycleTable, SlipEvents):
    the analysis' chain on a trace dict (``time``, ``spring_force``, optional
    ``wall_position``): detect the slips, tabulate the cycles and, with ``refine``,
    place each slip's static and backward force on its ramps' fitted lines."""
    from filmfriction.analysis.stickslip import detect_slips
    from filmfriction.analysis.stick_ramps import ramp_forces
    from filmfriction.reduced_model.cycles import cycle_table

    def table(trace, spring_constant, refine=True):
        t, f = trace["time"], trace["spring_force"]
        wall = trace.get("wall_position")
        events = detect_slips(t, f)
        tab = cycle_table(t, f, events.yield_index, events.stick_index,
                          spring_constant=spring_constant, wall_position=wall)
        if refine:
            tab = ramp_forces(t, f, tab, wall_position=wall)
        return tab, events
    return table
