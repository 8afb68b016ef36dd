"""Analysis of stick-slip traces and confined-film trajectories.

Modules (one sitting each):

* :mod:`analysis.stickslip` — yield/re-stick detection, cycle table, regime;
* :mod:`analysis.trace` — reading run directories and CSV traces;
* :mod:`analysis.energy` — energy partition per slip (Klein), MD ledger;
* :mod:`analysis.viscosity` — η_eff from steady sliding, velocity profiles,
  power-law fits across runs, and Klein's slip equation;
* :mod:`analysis.structure` — layers, hexatic order, gap (MDAnalysis);
* :mod:`analysis.report` — the ``analysis.json`` document;
* :mod:`analysis.cli` — ``filmfriction analyze``;
* :mod:`analysis.synthetic` — traces and films with known answers.
"""
