"""The experiments built on the vereshchagin library: the reproduction of both reports it comes from.

A package of its own (``pip install ./experiments``), so that the library carries no simulator,
figures or report writers. It needs ``vereshchagin``, ``mujoco`` and ``matplotlib``.

- :mod:`.friction_figures`: the static joint friction figures 5.2, 5.5 and 6.2-6.7 of D. Vukcevic
  (2018) and a table of the optimum found by ``Solver.solve(..., friction=...)`` next to the
  report's published numbers;
- :mod:`.gauss`: the report's slow evaluations of Vereshchagin's max-min (the Gauss function g(mu)
  by one frictionless solve per friction vector, grid sampling and vertex enumeration), drawn in
  those figures;
- :mod:`.contact`: the contact use cases of W. K. Lau (2023) and the dual-arm case, in a MuJoCo
  plant;
- :mod:`.friction_energy`, :mod:`.friction_energy_report`: the motor effort exact static friction
  saves on the Gen3;
- :mod:`.demo`: three tasks on a 7-joint arm.

Run everything with ``python -m vereshchagin_experiments reproduce --out results``.
"""
