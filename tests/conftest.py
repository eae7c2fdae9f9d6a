"""Shared pytest set-up of every test under tests/.

The tests are grouped by kind: ``unit/`` (the library's own behaviour), ``oracles/`` (checks
against external oracles: Pinocchio, KDL/PyKDL, SciPy, MuJoCo, the dense and enumeration
oracles), ``experiments/`` (the vereshchagin_experiments package) and ``docs/`` (docs build,
examples, README, public API docs, project files, packaging). Helper modules live in the package
``support`` (``tests/support/``), imported everywhere as ``from support.chains import ...``;
fixtures used by more than one file are defined here.
"""

import os
import sys

import pytest

# Make the helper package tests/support importable regardless of how pytest is invoked.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

collect_ignore = ["docs/cmake_consumer"]


@pytest.fixture(scope="module")
def gen3():
    """The shipped Kinova Gen3 (no gripper) as a Chain to ``end_effector_link``, one per module."""
    import vereshchagin as vs
    from vereshchagin.robots import gen3_urdf

    return vs.Chain.from_urdf(gen3_urdf(), tip="end_effector_link")


@pytest.fixture(scope="module")
def baxter():
    """example-robot-data's Baxter as a Tree, one per module."""
    import vereshchagin as vs
    from vereshchagin.robots import example_robot_urdf

    return vs.Tree.from_urdf(example_robot_urdf("baxter"))
