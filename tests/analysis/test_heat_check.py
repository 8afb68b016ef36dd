"""The energy checks that can fail: the film's heat from the wall's mechanics against an
independent tally of the heat (a thermostat's), on Klein slips whose heat is known."""
import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from filmfriction.analysis.energy.heat_check import compare_heat
from filmfriction.analysis.energy.partition import energy_table
from filmfriction.analysis.groundtruth.synthetic import klein_trace

# Klein's SFB numbers (SI): overdamped viscous slips
KLEIN = dict(spring_constant=97.0, mass=1.47e-3, damping=3.09,
             drive_velocity=100e-9, static_force=9.7e-6, backward_force=3.0e-6)
CYCLES = 8


def thermostat_column(tr, noise, seed):
    """What a thermostat on the film would tally: the viscous heat ∫B v² dt, plus the
    wall's kinetic energy when the film re-solidifies under it, plus thermal noise of
    standard deviation ``noise`` on every sample."""
    v, t = tr["wall_velocity"], tr["time"]
    q = cumulative_trapezoid(KLEIN["damping"] * v ** 2, t, initial=0.0)
    stops = np.flatnonzero((v[:-1] != 0) & (v[1:] == 0)) + 1
    for i in stops:
        q[i:] += 0.5 * KLEIN["mass"] * v[i - 1] ** 2
    return q + np.random.default_rng(seed).normal(0.0, noise, t.size)


@pytest.fixture(scope="module")
def klein():
    from filmfriction.analysis.stickslip import detect_slips
    from filmfriction.analysis.stick_ramps import ramp_forces
    from filmfriction.reduced_model.cycles import cycle_table
    tr = klein_trace(**KLEIN, cycles=CYCLES, noise=0.002 * KLEIN["static_force"], seed=4)
    t, f = tr["time"], tr["spring_force"]
    ev = detect_slips(t, f)
    tab = cycle_table(t, f, ev.yield_index, ev.stick_index,
                      spring_constant=KLEIN["spring_constant"], wall_position=tr["wall_position"])
    tab = ramp_forces(t, f, tab, wall_position=tr["wall_position"])
    assert len(tab) == CYCLES
    heat = (KLEIN["static_force"] ** 2 - KLEIN["backward_force"] ** 2) / (2 * KLEIN["spring_constant"])
    return tr, tab, ev, heat


def table(tr, tab, ev, *, force_scale=1.0, velocity_scale=1.0, thermostat_scale=1.0,
          mount_damping=0.0, noise=0.0, seed=0):
    q = thermostat_scale * thermostat_column(tr, noise, seed)
    return energy_table(tr["time"], force_scale * tr["spring_force"], tab,
                        KLEIN["spring_constant"], mass=KLEIN["mass"],
                        wall_velocity=velocity_scale * tr["wall_velocity"],
                        drive_position=tr["drive_position"], noise=ev.noise,
                        drive_velocity=KLEIN["drive_velocity"], mount_damping=mount_damping,
                        ledger_columns={"thermostat_heat": q})


def both(et):
    return (compare_heat(et.film_heat, et.thermostat_heat_slip, what="per slip"),
            compare_heat(et.film_heat_cycle, et.thermostat_heat_cycle, what="per cycle"))


def test_the_film_heat_agrees_with_the_thermostat_on_a_correct_trace(klein):
    tr, tab, ev, heat = klein
    exact = both(table(tr, tab, ev))           # against the noise-free tally
    for c in exact:
        assert abs(c.difference) < 0.01 * c.thermostat_heat, c.message
        # the spring's release (Fs² − Fb²)/2K plus the drive's work during the slip
        assert heat < c.film_heat < 1.1 * heat
    for c in both(table(tr, tab, ev, noise=0.05 * heat, seed=1)):
        assert c.status == "agree", c.message
        # the stated power: with 5 % thermal noise on the tally, a 10 % error is resolved
        assert 0 < c.resolution < 0.1


@pytest.mark.parametrize("spoil", [
    dict(thermostat_scale=0.85),            # a thermostat column that misses 15 % of the heat
    dict(force_scale=1.15),                 # a force column in the wrong units
    dict(velocity_scale=0.85),              # a velocity column in the wrong units
    dict(mount_damping=200.0),              # a mount dashpot the trace never had
])
def test_a_wrong_film_heat_or_tally_is_flagged(klein, spoil):
    tr, tab, ev, heat = klein
    for c in both(table(tr, tab, ev, noise=0.05 * heat, seed=1, **spoil)):
        assert c.status == "disagree", (spoil, c.message)


def test_the_checks_false_alarm_rate_is_the_stated_one(klein):
    # 99 % limits: a correct film heat is flagged in about 1 % of noisy tallies per slip.
    # The cycles share their end points, so the pairs' scatter overstates the error of their
    # mean (the tally's noise telescopes): the per-cycle check flags less often than stated
    tr, tab, ev, heat = klein
    flagged = {"slip": 0, "cycle": 0}
    z_cycle = []
    for seed in range(200):
        slip, cycle = both(table(tr, tab, ev, noise=0.05 * heat, seed=seed))
        flagged["slip"] += slip.status == "disagree"
        flagged["cycle"] += cycle.status == "disagree"
        z_cycle.append(cycle.z)
    assert flagged["slip"] <= 8 and flagged["cycle"] <= 8, flagged  # P(> 8 of 200) < 0.1 %
    assert np.std(z_cycle) < 1.0


def test_too_few_pairs_are_undetermined():
    c = compare_heat([1.0, 2.0, np.nan], [1.0, 2.0, 3.0])
    assert c.status == "undetermined" and "2 pair(s)" in c.message
    assert compare_heat([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]).status == "undetermined"


def test_the_quadrature_residual_does_not_see_a_wrong_thermostat(klein):
    # the per-slip balance is bookkeeping: with the engine's drive work and spring energy
    # it stays at zero whatever the thermostat says; the comparison sees the wrong heat
    tr, tab, ev, heat = klein
    t, f, xd = tr["time"], tr["spring_force"], tr["drive_position"]
    for scale in (1.0, 0.5):
        cols = {"thermostat_heat": scale * thermostat_column(tr, 0.0, 0),
                "spring_energy": f ** 2 / (2 * KLEIN["spring_constant"]),
                "drive_work": cumulative_trapezoid(f, xd, initial=0.0)}
        et = energy_table(t, f, tab, KLEIN["spring_constant"], mass=KLEIN["mass"],
                          wall_velocity=tr["wall_velocity"], drive_position=xd,
                          drive_velocity=KLEIN["drive_velocity"], ledger_columns=cols)
        assert np.all(np.abs(et.quadrature_residual) < 0.01), et.quadrature_residual
        status = compare_heat(et.film_heat, et.thermostat_heat_slip).status
        assert status == ("disagree" if scale == 0.5 else "agree")
    # what it does check: the trace against the engine's integrals (here a spring energy
    # column 10 % off, as with a wrong K)
    cols["spring_energy"] = 1.1 * cols["spring_energy"]
    et = energy_table(t, f, tab, KLEIN["spring_constant"], mass=KLEIN["mass"],
                      wall_velocity=tr["wall_velocity"], drive_position=xd,
                      drive_velocity=KLEIN["drive_velocity"], ledger_columns=cols)
    assert np.all(np.abs(et.quadrature_residual) > 0.05), et.quadrature_residual
