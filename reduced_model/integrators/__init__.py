"""How a spring-block run is integrated, one route per file.

* :mod:`~filmfriction.reduced_model.integrators.trajectory` — the problem, the recorder
  and the result every route returns;
* :mod:`~filmfriction.reduced_model.integrators.closed_form` — Coulomb friction cycle by
  cycle in closed form (the damped oscillator of
  :mod:`~filmfriction.reduced_model.integrators.oscillator`);
* :mod:`~filmfriction.reduced_model.integrators.event_driven` — any law: an ODE solver
  between exact stick/slip events; its fast path for stateless laws with static
  friction is :mod:`~filmfriction.reduced_model.integrators.dop853_slip`;
* :mod:`~filmfriction.reduced_model.integrators.limit_cycle` and
  :mod:`~filmfriction.reduced_model.integrators.smooth_steps` — the rate-and-state fast
  path (compiled steps to the limit cycle);
* :mod:`~filmfriction.reduced_model.integrators.rk45` — a fixed-law Runge-Kutta reference.
"""
