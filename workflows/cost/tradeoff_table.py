"""What the trade study measures and tabulates: the observables, a setting's
measurement and its error against the reference (with the uncertainty of that error),
the table's columns, ``tradeoff.csv`` and the text summary."""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from filmfriction.analysis.files.util import write_atomic


# name -> unit; the order is the order of the table's columns
OBSERVABLES = {
    "static_force": "epsilon/sigma",
    "slip_distance": "sigma",
    "period": "tau",
    "eta_eff": "epsilon tau/sigma^3",
    "ledger_closure": "1",
    "energy_drift": "epsilon/tau",
}


# observables whose value grows with the contact area: scaled to the base area
EXTENSIVE = {"static_force", "energy_drift"}


COST_FIELDS = ("cost_seconds", "cost_seconds_per_tau", "cost_seconds_per_cycle",
               "atom_steps_per_second", "memory_peak_rss_mb", "memory_lammps_mb_per_rank",
               "atoms", "steps", "simulated_tau", "cycles")


# ----------------------------------------------------------------- measuring
@dataclass(frozen=True)
class Measurement:
    """Observables of one setting: name -> (mean, standard error)."""

    values: dict
    cycles: int
    regime: str
    area: float


def value_and_error(entry) -> tuple[float, float]:
    if not entry:
        return math.nan, math.nan
    mean, se = entry.get("mean"), entry.get("stderr")
    return (math.nan if mean is None else float(mean)), (math.nan if se is None else float(se))


def drift(time_, residual, blocks: int = 5) -> tuple[float, float]:
    """Slope of the ledger residual with its standard error from block slopes.

    Parameters
    ----------
    time_, residual : array
        Time and the cumulative ledger residual (zero at the start).
    blocks : int
        Equal-time blocks; the spread of their mean slopes gives the error.

    Returns
    -------
    (slope, stderr) : tuple of float
    """
    t = np.asarray(time_, float)
    r = np.asarray(residual, float)
    if t.size < 2 or t[-1] <= t[0]:
        return math.nan, math.nan
    slope = (r[-1] - r[0]) / (t[-1] - t[0])
    edges = np.linspace(t[0], t[-1], blocks + 1)
    idx = np.searchsorted(t, edges)
    idx[-1] = t.size - 1
    slopes = [(r[b] - r[a]) / (t[b] - t[a]) for a, b in zip(idx[:-1], idx[1:]) if t[b] > t[a]]
    se = float(np.std(slopes, ddof=1) / math.sqrt(len(slopes))) if len(slopes) > 1 else math.nan
    return float(slope), se


def combine(measurements: list[Measurement]) -> Measurement:
    """One setting's runs with different seeds as one measurement: each observable's mean
    over the runs, with the standard error of that mean over the runs (the runs' own
    standard errors for a single run).  Cycles add up; the regime is the runs' regimes."""
    if len(measurements) == 1:
        return measurements[0]
    values = {}
    for name in measurements[0].values:
        means = np.array([m.values[name][0] for m in measurements], float)
        ok = means[np.isfinite(means)]
        values[name] = ((float(ok.mean()), float(ok.std(ddof=1) / math.sqrt(ok.size)))
                        if ok.size > 1 else
                        (float(ok[0]) if ok.size else math.nan, math.nan))
    regimes = sorted({m.regime for m in measurements})
    return Measurement(values=values, cycles=sum(m.cycles for m in measurements),
                       regime=regimes[0] if len(regimes) == 1 else "mixed: " + ", ".join(regimes),
                       area=measurements[0].area)


def compare(setting: Measurement, reference: Measurement, is_reference: bool) -> dict:
    """``error_<obs>`` = setting − reference with ``error_<obs>_uncertainty``.

    The uncertainty combines both standard errors in quadrature; for a run
    compared with itself both are zero.  A missing standard error (fewer
    than two cycles) gives a NaN uncertainty: the error is then not tested.
    """
    row = {}
    for name in OBSERVABLES:
        m, s = setting.values[name]
        mr, sr = reference.values[name]
        row[f"value_{name}"] = m
        if is_reference:
            row[f"error_{name}"], row[f"error_{name}_uncertainty"] = 0.0, 0.0
        else:
            row[f"error_{name}"] = m - mr
            row[f"error_{name}_uncertainty"] = math.hypot(s, sr)
    return row


def columns() -> list[str]:
    cols = ["knob", "value", "reference", *COST_FIELDS, "regime", "seeds"]
    for name in OBSERVABLES:
        cols += [f"value_{name}", f"error_{name}", f"error_{name}_uncertainty"]
    return cols + ["run_dir"]


def write_csv(rows: list[dict], path: Path) -> Path:
    cols = columns()
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore")
    w.writeheader()
    for row in rows:
        w.writerow({c: _fmt(row.get(c)) for c in cols})
    return write_atomic(path, buf.getvalue())


def _fmt(v):
    if isinstance(v, float):
        return "" if not math.isfinite(v) else f"{v:.6g}"
    return "" if v is None else v


def summary(rows: list[dict]) -> str:
    """A text table: cost and the relative error ± uncertainty of Fs, slip, period, eta."""
    head = f"{'knob':20s} {'value':26s} {'s':>7s} {'s/tau':>7s} {'MB':>6s}"
    names = ("static_force", "slip_distance", "period", "eta_eff", "energy_drift")
    head += "".join(f" {n[:12]:>19s}" for n in names)
    lines = [head]
    for r in rows:
        line = (f"{r['knob']:20s} {r['value'] + (' (ref)' if r['reference'] else ''):26s} "
                f"{_g(r.get('cost_seconds'), 7)} {_g(r.get('cost_seconds_per_tau'), 7)} "
                f"{_g(r.get('memory_peak_rss_mb'), 6)}")
        for n in names:
            e, u = r.get(f"error_{n}"), r.get(f"error_{n}_uncertainty")
            line += f" {_g(e, 9)}±{_g(u, 9, left=True)}"
        lines.append(line)
    return "\n".join(lines)


def _g(v, width, left=False):
    text = "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.3g}"
    return f"{text:<{width}s}" if left else f"{text:>{width}s}"
