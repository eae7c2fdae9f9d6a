"""Reproductions of the static joint friction experiments of D. Vukcevic (2018), chapters 5-6.

- :mod:`.gauss`: the slow reference evaluations of Vereshchagin's max-min (the Gauss function
  g(mu) by one frictionless solve per friction vector, grid sampling and vertex enumeration),
  kept for tests and figures;
- :mod:`.friction_figures`: the report's figures 5.2, 5.5 and 6.2-6.7 and a table of the optimum
  found by ``Solver.solve(..., friction=...)`` next to the report's published numbers.

Run everything with ``python -m vereshchagin reproduce --out results``.
"""
