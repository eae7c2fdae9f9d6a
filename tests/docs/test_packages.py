"""Two packages (issue 25): the library carries no simulator, figures or report writers.

``vereshchagin`` (the library, repository root) depends on numpy only; ``vereshchagin-experiments``
(``experiments/``) holds the reproduction of both reports, the MuJoCo plant and the figures, and
depends on the library.
"""

import re
import subprocess
import sys
from importlib import metadata

HEAVY = ("mujoco", "matplotlib", "scipy", "pinocchio", "example_robot_data")


def plain_requirements(dist):
    """Requirement names of a distribution outside its extras."""
    names = []
    for req in metadata.requires(dist) or []:
        if "extra ==" in req:
            continue
        names.append(re.split(r"[ ;<>=!~\[]", req, maxsplit=1)[0].lower())
    return names


def test_the_library_needs_only_numpy():
    assert plain_requirements("vereshchagin") == ["numpy"]


def test_the_experiments_depend_on_the_library_and_bring_the_plant():
    assert {"vereshchagin", "mujoco", "matplotlib"} <= set(plain_requirements("vereshchagin-experiments"))


def test_the_library_imports_and_solves_without_the_heavy_packages():
    blocked = repr(HEAVY)
    code = f"""
import sys, importlib.abc
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {blocked}:
            raise ModuleNotFoundError(name)
        return None
sys.meta_path.insert(0, Block())
import numpy as np
import vereshchagin as vs
chain = vs.Chain()
tip = np.eye(4)
tip[0, 3] = 1.0
chain.add_segment("link", "rot_z", tip=tip, mass=1.0, com=[-0.5, 0.0, 0.0], inertia=np.diag([0.0, 1 / 12, 1 / 12]))
print(repr(float(vs.Solver(chain, gravity=[0.0, -9.81, 0.0]).solve([0.0], [0.0]).qdd[0])))
print(sorted(m for m in sys.modules if m.split(".")[0] in {blocked}))
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    qdd_line, imported = proc.stdout.splitlines()
    assert imported == "[]"
    # A uniform rod (com in the tip frame, KDL's convention) about its end: qdd = -3 g / (2 l).
    assert abs(float(qdd_line) + 3 * 9.81 / 2) < 1e-12


def test_the_library_package_holds_no_experiments():
    import vereshchagin

    files = metadata.files("vereshchagin")
    names = {str(f) for f in files}
    assert not any(n.startswith(("vereshchagin/contact/", "vereshchagin/experiments")) for n in names)
    assert not hasattr(vereshchagin, "contact")
