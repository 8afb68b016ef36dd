"""The contract every registered friction law passes, with no per-law code here.

Each law declares ``example()`` (typical parameters for a block with M = K = N = 1
driven at V = 0.1) and ``invalid_examples()`` (changes to the example that the
constructor must refuse); this file runs every class in ``laws.registered()``
through the same checks:

* the law is a frozen dataclass, and ``example()`` builds an instance of it;
* friction opposes the slip, ``friction`` and ``sliding_force`` describe one
  curve, and a law's hot-loop closure (``scalar_sliding``, ``scalar_state_rates``) is that curve;
* a run of the example closes its energy ledger (closed form <= 1e-10, ODE path
  <= 1e-8, as the rest of the suite asks) and friction only takes energy out;
* each invalid example, and NaN in any real parameter, raises ``ValueError``
  whose message starts with the parameter's name;
* where ``method="auto"`` takes a closed form, it is what ``"closed_form"`` gives,
  and the ODE path agrees with it over several stick-slip cycles; laws with no
  closed form refuse ``method="closed_form"`` and the check is skipped, saying so.

:class:`PowerLawDrag` below is a user's law written in a file of its own (this
one): subclassing ``FrictionLaw`` registers it, so it runs through the same contract.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import re

import numpy as np
import pytest

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.laws.base import FrictionLaw, at_least, non_negative, positive


# ----------------------------------------------------------------------------- a user's law
@dataclasses.dataclass(frozen=True)
class PowerLawDrag(FrictionLaw):
    """Coulomb friction plus a power-law drag: ``F = N mu_k + c v**p``, static threshold ``mu_s N``."""

    static: float
    kinetic: float
    drag: float
    power: float = 0.5

    def __post_init__(self):
        non_negative("PowerLawDrag.kinetic", self.kinetic, "a friction coefficient")
        at_least("PowerLawDrag.static", self.static, "kinetic", self.kinetic)
        non_negative("PowerLawDrag.drag", self.drag, "negative drag would feed energy")
        positive("PowerLawDrag.power", self.power, "the drag vanishes at rest")

    @classmethod
    def example(cls):
        return cls(static=1.0, kinetic=0.5, drag=0.2)

    @classmethod
    def invalid_examples(cls):
        return [{"kinetic": -0.1}, {"static": 0.4}, {"drag": -0.1}, {"power": 0.0}]

    def sliding_force(self, speed, state, normal_load):
        return normal_load * self.kinetic + self.drag * speed ** self.power

    def static_force(self, state, normal_load):
        return self.static * normal_load


# ----------------------------------------------------------------------------- the checks
LAWS = laws.registered()       # after the class statement above: the user's law is among them
V, DURATION = 0.1, 120.0       # ~9 stick-slip cycles of the examples
CLOSURE = {"closed form": 1e-10, "ODE": 1e-8}


def _name(cls):
    return cls.__name__


def _block(law, **kw):
    return SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=V, damping=0.02, law=law, **kw)


def _smooth(law):
    return law.static_force(law.steady_state(V), 1.0) is None


def _run(law, **kw):
    # a smooth law starts in steady sliding: kick it, or nothing would happen
    start = {"initial_velocity": 1.3 * V} if _smooth(law) else {}
    return _block(law).simulate(DURATION, **start, **kw)


def check_ledger(cls):
    law = cls.example()
    path = "closed form" if law.closed_form(1.0) is not None else "ODE"
    r = _run(law)
    assert r.status == 0, r.message
    assert r.energy.closure <= CLOSURE[path], (path, r.energy)
    # friction only takes energy out: a sign slip in a law shows here, not in the closure
    assert r.energy.friction_dissipation > 0.0, r.energy
    assert np.all(np.diff(r.friction_dissipation) >= -1e-12 * r.energy.friction_dissipation)
    if not _smooth(law):
        kinds = [e.kind for e in r.events]
        assert "slip" in kinds, f"the example never breaks away in {DURATION} time units: {kinds}"


def check_friction_curve(cls):
    law = cls.example()
    state = law.steady_state(V)
    for speed in (1e-4, 1e-2, 0.1, 0.5, 2.0, 20.0):
        ahead, back = law.friction(speed, state, 1.0), law.friction(-speed, state, 1.0)
        assert ahead >= 0.0 and back == pytest.approx(-ahead, rel=1e-12), (speed, ahead, back)
        assert float(law.sliding_force(speed, state, 1.0)) == pytest.approx(ahead, rel=1e-12)
        if not law.state_names:
            assert law.scalar_sliding(1.0)(speed) == pytest.approx(ahead, rel=1e-12)
        rates = law.scalar_state_rates(1.0)
        if rates is not None:       # the smooth fast path's closure is the same law
            for s in (speed, -speed):
                fr, rate = rates(s, [float(c) for c in state])
                assert fr == pytest.approx(law.friction(s, state, 1.0), rel=1e-12)
                np.testing.assert_allclose(rate, law.state_rate(speed, state), rtol=1e-12)
    assert law.friction(0.0, state, 1.0) == 0.0


def check_fast_path(cls):
    law = cls.example()
    if law.closed_form(1.0) is None:
        with pytest.raises(ValueError, match="no closed form"):
            _run(law, method="closed_form")
        pytest.skip(f"{cls.__name__} has no closed form: method='auto' takes the ODE path")
    auto, closed, ode = _run(law), _run(law, method="closed_form"), _run(law, method="ode")
    np.testing.assert_array_equal(auto.x, closed.x)            # auto took the closed form
    assert [e.kind for e in ode.events] == [e.kind for e in closed.events]
    if not _smooth(law):
        assert sum(e.kind == "stick" for e in closed.events) >= 3, "fewer than 3 cycles to compare"
    for a, b in zip(closed.events, ode.events):
        assert b.time == pytest.approx(a.time, abs=1e-7)
        assert b.spring_force == pytest.approx(a.spring_force, abs=1e-8)
    assert ode.x[-1] == pytest.approx(closed.x[-1], abs=1e-8)
    assert ode.v[-1] == pytest.approx(closed.v[-1], abs=1e-8)
    assert ode.energy.friction_dissipation == pytest.approx(closed.energy.friction_dissipation, rel=1e-9)


def _starts_with_parameter(message, names):
    return any(re.match(rf"(\w+\.)?{re.escape(n)} = ", message) for n in names)


def check_refused(cls, change):
    with pytest.raises(ValueError) as caught:
        dataclasses.replace(cls.example(), **change)
    assert _starts_with_parameter(str(caught.value), change), (change, str(caught.value))


def _real_parameters(cls):
    example = cls.example()
    return [f.name for f in dataclasses.fields(example) if f.init
            and isinstance(getattr(example, f.name), numbers.Real)
            and not isinstance(getattr(example, f.name), bool)]


# ----------------------------------------------------------------------------- the tests
@pytest.mark.parametrize("cls", LAWS, ids=_name)
def test_example_is_a_frozen_law_of_its_class(cls):
    law = cls.example()
    assert type(law) is cls, f"{cls.__name__}.example() built a {type(law).__name__}"
    assert dataclasses.is_dataclass(law) and cls.__dataclass_params__.frozen
    assert cls.invalid_examples(), f"{cls.__name__}.invalid_examples() declares nothing to refuse"


@pytest.mark.parametrize("cls", LAWS, ids=_name)
def test_friction_opposes_slip(cls):
    check_friction_curve(cls)


@pytest.mark.parametrize("cls", LAWS, ids=_name)
def test_ledger_closes(cls):
    check_ledger(cls)


@pytest.mark.parametrize("cls, change", [(cls, change) for cls in LAWS for change in cls.invalid_examples()],
                         ids=lambda p: p.__name__ if isinstance(p, type) else ",".join(f"{k}={v!r}" for k, v in p.items()))
def test_invalid_parameters_refused(cls, change):
    check_refused(cls, change)


@pytest.mark.parametrize("cls", LAWS, ids=_name)
def test_nan_refused(cls):
    names = _real_parameters(cls)
    assert names, f"{cls.__name__} has no real-valued parameter"
    for name in names:
        check_refused(cls, {name: math.nan})


@pytest.mark.parametrize("cls", LAWS, ids=_name)
def test_fast_path_agrees_with_ode(cls):
    check_fast_path(cls)


# ----------------------------------------------------------------------------- the registry
def test_every_law_of_the_package_is_registered_and_exported():
    package = {name: obj for name, obj in vars(laws).items()
               if isinstance(obj, type) and issubclass(obj, FrictionLaw) and obj is not FrictionLaw}
    assert len(package) >= 10
    for name, cls in package.items():
        assert laws.REGISTRY[name] is cls and cls in laws.registered() and name in laws.__all__
    for name, cls in laws.REGISTRY.items():
        if cls.__module__.startswith("filmfriction.reduced_model.laws."):
            assert getattr(laws, name) is cls
    assert callable(laws.newtonian_damping) and callable(laws.carreau_viscosity)


def test_a_users_law_registers_by_subclassing():
    assert laws.REGISTRY["PowerLawDrag"] is PowerLawDrag
    assert PowerLawDrag in LAWS and not hasattr(laws, "PowerLawDrag")


def test_registration_opt_out_and_name_clash():
    @dataclasses.dataclass(frozen=True)
    class Helper(PowerLawDrag, register=False):
        pass
    assert "Helper" not in laws.REGISTRY
    with pytest.raises(TypeError, match="'Coulomb' .* already registered"):
        type("Coulomb", (FrictionLaw,), {})


# ----------------------------------------------------------------------------- the contract can fail
@dataclasses.dataclass(frozen=True)
class FeedsEnergy(PowerLawDrag, register=False):
    """A sign slip: friction pushes the block along instead of holding it back."""

    def sliding_force(self, speed, state, normal_load):
        return -super().sliding_force(speed, state, normal_load)


@dataclasses.dataclass(frozen=True)
class AcceptsAnything(PowerLawDrag, register=False):
    """Validation forgotten."""

    def __post_init__(self):
        pass


def test_the_contract_catches_broken_laws():
    with pytest.raises(AssertionError):
        check_ledger(FeedsEnergy)
    with pytest.raises(AssertionError):
        check_friction_curve(FeedsEnergy)
    with pytest.raises(pytest.fail.Exception):
        check_refused(AcceptsAnything, {"kinetic": -0.1})


def test_type_checkers_see_every_law():
    """``laws/__init__.py`` names every registered law for type checkers (which do
    not run the registration): its ``if TYPE_CHECKING`` block lists exactly the laws."""
    import ast
    from pathlib import Path

    from filmfriction.reduced_model import laws as laws_package

    tree = ast.parse(Path(laws_package.__file__).read_text())
    block = next(n for n in tree.body if isinstance(n, ast.If)
                 and getattr(n.test, "id", None) == "TYPE_CHECKING")
    named = {a.name for n in block.body for a in n.names}
    assert named == set(laws_package._LAWS), named ^ set(laws_package._LAWS)
