"""Helpers shared by the tests, imported the same way everywhere: ``from support.chains import ...``.

``tests/conftest.py`` puts ``tests/`` on ``sys.path``; the test files are grouped by kind in
``tests/unit``, ``tests/oracles``, ``tests/experiments`` and ``tests/docs``. Modules:

* :mod:`support.chains`: random serial chains built as a vereshchagin Chain and a Pinocchio model,
  and small numeric helpers (``assert_close``, ``symmetric``, ...);
* :mod:`support.trees`: random URDF trees, Pinocchio joint maps, and the robots of the tree tests;
* :mod:`support.urdf_robots`: the URDF robots (Panda, UR5, Gen3) loaded by both libraries;
* :mod:`support.dense_oracle`: the dense Gauss formulation of the constrained solve;
* :mod:`support.friction_oracles`: the static-friction oracles (SLSQP, enumeration, MuJoCo);
* :mod:`support.friction_checks`: every check of a friction-aware solve against those oracles;
* :mod:`support.pykdl_checks`: checks against Debian's PyKDL (also run as a script by
  ``/usr/bin/python3``, so it imports nothing from this package).
"""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
"""The repository root."""
