"""A measured trace's slip, as the SFB check takes it, from its ``analysis.json``.

The analysis of an SI trace (``filmfriction analyze --units si``) gives what
:class:`filmfriction.reduced_model.sfb.user_setup.MeasuredSlip` needs: the mean static
force F_s, slip distance Δx0, slip time τ_s and period, each with its standard
error, and η_eff of Klein's Eq. 1 fitted to the slips.

Example
-------
>>> doc = {"units": "si", "source": {"path": "sfb.tsv"},
...        "slips": {"static_force": {"mean": 9.7e-6, "stderr": 2e-9},
...                  "slip_distance": {"mean": 7.3e-8, "stderr": 1e-10},
...                  "slip_duration": {"mean": 0.03, "stderr": 1e-4},
...                  "period": {"mean": 0.73, "stderr": 1e-3}},
...        "viscosity": {"from_slip": {"eta_eff": {"mean": 27.0, "stderr": 0.5}}}}
>>> slip = measured_slip(doc)
>>> slip.static_force, slip.eta_eff_err, slip.source
(9.7e-06, 0.5, 'sfb.tsv')
"""
from __future__ import annotations

import math

from filmfriction.reduced_model.sfb.user_setup import MeasuredSlip
from filmfriction.md_inputs.contract import ANALYSIS_FILE

__all__ = ["measured_slip"]


def _entry(doc: dict, section: str, key: str, where: str) -> tuple[float, float]:
    e = ((doc.get(section) or {}).get(key) if section != "viscosity"
         else ((doc.get("viscosity") or {}).get("from_slip") or {}).get(key))
    mean = (e or {}).get("mean")
    if mean is None or not math.isfinite(float(mean)) or float(mean) <= 0:
        why = (doc.get("skipped") or {}).get("viscosity.from_slip" if section == "viscosity"
                                              else f"slips.{key}", "")
        raise ValueError(f"{where}: no {section}.{key} in the analysis"
                         + (f" ({why})" if why else " (a trace with slips, analysed with "
                            "--spring-constant, --mass, --area and --thickness, gives it)"))
    err = (e or {}).get("stderr")
    return float(mean), float(err) if err is not None and math.isfinite(float(err)) else 0.0


def measured_slip(doc: dict, where: str = ANALYSIS_FILE) -> MeasuredSlip:
    """The :class:`MeasuredSlip` of an SI trace's ``analysis.json`` document.

    Raises
    ------
    ValueError
        An analysis in LJ units (an MD run's), or one without slips or η_eff.
    """
    if doc.get("units") != "si":
        raise ValueError(f"{where}: the analysis is in {doc.get('units', 'lj')!r} units; a "
                         "measured slip is SI (analyse the trace with --units si)")
    fs, fs_err = _entry(doc, "slips", "static_force", where)
    dx, dx_err = _entry(doc, "slips", "slip_distance", where)
    ts, ts_err = _entry(doc, "slips", "slip_duration", where)
    period, _ = _entry(doc, "slips", "period", where)
    eta, eta_err = _entry(doc, "viscosity", "eta_eff", where)
    return MeasuredSlip(static_force=fs, slip_distance=dx, slip_time=ts, cycle_time=period,
                        eta_eff=eta, static_force_err=fs_err, slip_distance_err=dx_err,
                        slip_time_err=ts_err, eta_eff_err=eta_err,
                        source=str((doc.get("source") or {}).get("path") or where))
