"""Analysis of stick-slip traces and confined-film trajectories.

Modules (one sitting each):

* :mod:`filmfriction.analysis.stickslip` — yield/re-stick detection, cycle table, regime;
* :mod:`filmfriction.analysis.trace` — reading run directories and CSV traces;
* :mod:`filmfriction.analysis.energy` — energy partition per slip (Klein), MD ledger;
* :mod:`filmfriction.analysis.viscosity` — η_eff from steady sliding, velocity profiles,
  power-law fits across runs, and Klein's slip equation;
* :mod:`filmfriction.analysis.structure` — layers, hexatic order, gap (MDAnalysis);
* :mod:`filmfriction.analysis.report` — the ``analysis.json`` document;
* * :mod:`filmfriction.analysis.synthetic` — traces and films with known answers.
"""

if __name__ != "filmfriction.analysis":  # one name only: two would give two copies of every class
    raise ImportError(f"import filmfriction.analysis, not {__name__}")
