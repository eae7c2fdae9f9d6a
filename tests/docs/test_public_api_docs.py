"""Every public class, function, method, property and field has a docstring, and the stubs match
the runtime (mypy's stubtest)."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import re
import subprocess
import sys

import pytest

import vereshchagin as vs
from support import ROOT

# Modules whose public names are API: the package, its submodules and subpackages.
MODULES = sorted(
    {"vereshchagin"}
    | {m.name for m in pkgutil.walk_packages(vs.__path__, "vereshchagin.") if not m.name.split(".")[-1].startswith("_")}
)


def _public(obj):
    names = getattr(obj, "__all__", None)
    if names is None:
        names = [n for n in dir(obj) if not n.startswith("_")]
    return names


SIGNATURE = re.compile(r"^(\w+)?\(.*\)( -> .*)?$")  # pybind11's generated 'name(self: T, ...) -> R'


def _documented(obj) -> bool:
    """A docstring with text beyond generated signature lines."""
    doc = inspect.getdoc(obj) or ""
    text = [line for line in doc.splitlines() if line.strip() and not SIGNATURE.match(line.strip())]
    return bool(text)


def _members(cls):
    """(name, object) of a class's own public API: methods, properties, dataclass fields."""
    out = []
    fields = {f.name for f in dataclasses.fields(cls)} if dataclasses.is_dataclass(cls) else set()
    for name, value in vars(cls).items():
        if name.startswith("_") or name in fields:
            continue
        out.append((name, value))
    return out, fields


def _field_documented(cls, field: str) -> bool:
    """A dataclass field is documented in its class's 'Attributes' or 'Parameters' section."""
    doc = inspect.getdoc(cls) or ""
    for line in doc.splitlines():
        head = line.split(" : ")[0] if " : " in line else line.rstrip(":")
        if field in (name.strip() for name in head.split(",")):
            return True
    return False


def _walk():
    seen = set()
    for modname in MODULES:
        mod = importlib.import_module(modname)
        yield f"{modname}", mod
        for name in _public(mod):
            obj = getattr(mod, name, None)
            if obj is None or inspect.ismodule(obj) or id(obj) in seen:
                continue
            owner = getattr(obj, "__module__", "") or ""
            if not owner.startswith("vereshchagin"):
                continue  # re-exported third-party names (numpy, typing, ...)
            seen.add(id(obj))
            yield f"{modname}.{name}", obj
            if inspect.isclass(obj):
                members, fields = _members(obj)
                for mname, member in members:
                    yield f"{modname}.{name}.{mname}", member
                for field in fields:
                    yield f"{modname}.{name}.{field} (field)", (obj, field)


def test_every_public_object_has_a_docstring():
    missing = []
    count = 0
    for qualname, obj in _walk():
        count += 1
        if isinstance(obj, tuple):  # dataclass field
            if not _field_documented(*obj):
                missing.append(qualname)
            continue
        if isinstance(obj, property):
            ok = _documented(obj) or _documented(obj.fget)  # pybind11 documents the property itself
        elif isinstance(obj, (staticmethod, classmethod)):
            ok = _documented(obj.__func__)
        else:
            ok = _documented(obj)
        if not ok:
            missing.append(qualname)
    assert count > 100, f"the walk found only {count} public objects"
    assert not missing, "public objects without a docstring:\n  " + "\n  ".join(missing)


@pytest.mark.parametrize(
    "name",
    [
        "qdd",
        "tau_command",
        "nu",
        "link_acc",
        "constraint_rank",
        "smallest_singular_value",
        "friction_torque",
        "limit_torque",
        "status",
        "gauss_value",
        "iterations",
        "segment_nu",
    ],
)
def test_solve_result_fields_say_shape_and_units(name):
    doc = inspect.getdoc(getattr(vs.SolveResult, name))
    assert doc and len(doc) > 40, f"SolveResult.{name}: {doc!r}"


def test_solve_has_a_full_docstring_and_signature():
    doc = inspect.getdoc(vs.Solver.solve)
    for section in (
        "Parameters",
        "Returns",
        "Raises",
        "alpha",
        "beta",
        "f_ext",
        "friction",
        "constraints",
        "out",
        "a_desired",
        "contacts",
        "time_step",
        "contact_velocity_tolerance",
        "contact_max_pivots",
    ):
        assert section in doc, section
    params = list(inspect.signature(vs.Solver.solve).parameters)
    assert params == [
        "self",
        "q",
        "qd",
        "alpha",
        "beta",
        "f_ext",
        "tau_ff",
        "friction",
        "constraints",
        "f_ext_pass_through",
        "tau_ff_pass_through",
        "out",
        "a_desired",
        "contacts",
        "time_step",
        "contact_velocity_tolerance",
        "contact_max_pivots",
    ]


def test_stubs_match_the_runtime():
    """mypy's stubtest over the installed package (allowlist: pybind11's metaclass and the like)."""
    cmd = [
        sys.executable,
        "-m",
        "mypy.stubtest",
        "vereshchagin",
        "--mypy-config-file",
        str(ROOT / "pyproject.toml"),
        "--allowlist",
        str(ROOT / "tests" / "docs" / "stubtest_allowlist.txt"),
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT / "tests" / "docs", timeout=600)
    assert proc.returncode == 0, proc.stdout[-6000:] + proc.stderr[-2000:]
