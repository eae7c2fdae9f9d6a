"""SolveResult's pickling, copies, ``segment_nu`` and repr, written in Python over the compiled type.

The compiled ``_core.SolveResult`` keeps only the storage, its array views and the solve path's
fast access (``python/bindings/result_type.cpp``). Its pickle state is the 14-tuple of
``_result_state``: ``(n_joints, n_segments, m, friction, smallest_singular_value, gauss_value,
constraint_rank, iterations, data, keys, starts, counts, contacts, contact_outcome)`` (states of
12 entries, from before contacts, load with none); the compiled type holds the segment
layout as one tuple of ``(key, start, count)`` triples. A state is checked here (crafted states
raise ``ValueError``) before ``_core._result_from_parts`` allocates a result.
"""

from __future__ import annotations

from ._core import SolveResult, _result_from_parts
from ._docstrings import DOCS
from .contacts import ContactOutcome

_MAX_SIZE = 1 << 24  # joints or segments of a result
_INT_MAX = 2**31 - 1


def _int(value, hi: int, what: str, lo: int = 0) -> int:
    """``value`` as an int entry of a state within ``[lo, hi]``.

    Raises
    ------
    ValueError
        ``value`` is not an int (bool is refused) or is out of range; the message names ``what``.
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"SolveResult state: {what} must be an int")
    if not lo <= value <= hi:
        raise ValueError(f"SolveResult state: {what} is out of range ({lo} .. {hi})")
    return value


def _check_segment_layout(keys, starts, counts, m: int) -> None:
    """Checks a ``segment_nu`` layout: tuples of equal length, each part inside ``nu`` (m entries).

    Raises
    ------
    ValueError
        The layout is malformed or a part lies beyond ``nu``.
    """
    if not all(isinstance(x, tuple) for x in (keys, starts, counts)):
        raise ValueError("SolveResult state: segment layout entries must be tuples or None")
    if not len(keys) == len(starts) == len(counts):
        raise ValueError("SolveResult state: segment layout of inconsistent lengths")
    for start, count in zip(starts, counts):
        if _int(start, m, "segment layout start") + _int(count, m, "segment layout count") > m:
            raise ValueError("SolveResult state: segment layout beyond nu")


def _result_from_state(*state) -> SolveResult:
    """Unpickles a SolveResult from the entries of its state (see the module docstring).

    Returns
    -------
    SolveResult
        A new result holding the state's data bit for bit.

    Raises
    ------
    ValueError
        The state is malformed: wrong entry count, sizes out of range, data of the wrong length,
        a segment layout that does not fit ``nu``.
    """
    if len(state) not in (12, 14):
        raise ValueError("SolveResult state must have 14 entries (12 without contacts)")
    nj = _int(state[0], _MAX_SIZE, "n_joints")
    ns = _int(state[1], _MAX_SIZE, "n_segments")
    contacts, outcome = state[12:] if len(state) == 14 else (0, 0)
    sizes = (
        nj,
        ns,
        _int(state[2], 6 * ns, "m"),
        _int(state[3], 1, "the friction flag"),
        _int(contacts, _MAX_SIZE, "contacts"),
    )
    outcome = _int(outcome, 2, "the contact outcome")
    rank = _int(state[6], _INT_MAX, "rank", -_INT_MAX)
    iterations = _int(state[7], _INT_MAX, "iterations", -_INT_MAX)
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in state[4:6]):
        raise ValueError("SolveResult state: smin and gauss must be floats")
    if not isinstance(state[8], bytes):
        raise ValueError("SolveResult state: data must be bytes")
    layout = None
    if state[9] is not None:
        _check_segment_layout(state[9], state[10], state[11], sizes[2])
        layout = tuple(zip(state[9], state[10], state[11]))
    return _result_from_parts(sizes, (rank, state[4], state[5], iterations, outcome), state[8], layout)


def _result_state(self: SolveResult) -> tuple:
    """The pickle state (see the module docstring): the layout, the scalars as stored (0 where a
    solve without friction reports None), the storage's bytes (``_data``) and the segment layout."""
    gauss, iterations = self.gauss_value, self.iterations
    triples = self._segment_layout
    layout = (None, None, None) if triples is None else tuple(zip(*triples))
    sizes = (len(self.qdd), len(self.link_acc) - 1, len(self.nu), int(self.friction_torque is not None))
    scalars = (self.smallest_singular_value, 0.0 if gauss is None else gauss, self.constraint_rank)
    contacts = (len(self.contact_status), self._contact_outcome)
    return (*sizes, *scalars, 0 if iterations is None else iterations, self._data.tobytes(), *layout, *contacts)


def _reduce(self: SolveResult):
    """Pickle support: the state of ``_result_state``, restored by ``_result_from_state``."""
    return _result_from_state, _result_state(self)


def _copy(self: SolveResult) -> SolveResult:
    """An independent copy (its own data)."""
    return _result_from_state(*_result_state(self))


def _deepcopy(self: SolveResult, memo: object, /) -> SolveResult:
    """An independent copy (its own data); ``memo`` is unused (a result refers to no objects)."""
    return _copy(self)


def _segment_nu(self: SolveResult):
    """``{key: nu_i}`` for each ``constraints`` key (views into ``nu``), or None."""
    layout = self._segment_layout
    if layout is None:
        return None
    nu = self.nu
    return {key: nu[start : start + count] for key, start, count in layout}


def _contact_outcome(self: SolveResult) -> ContactOutcome:
    """How the contact forces were determined (``ContactOutcome.NONE`` without contacts)."""
    return ContactOutcome(self._contact_outcome)


def _repr(self: SolveResult) -> str:
    """``<vereshchagin.SolveResult n_joints=7 m=6 rank=6 friction>`` (" friction": a friction solve)."""
    friction = " friction" if self.friction_torque is not None else ""
    return f"<vereshchagin.SolveResult n_joints={len(self.qdd)} m={len(self.nu)} rank={self.constraint_rank}{friction}>"


# Attached to the compiled type (its stub declares them; setattr because a type checker rejects
# assigning to a declared method).
for _name, _value in [
    ("__repr__", _repr),
    ("__reduce__", _reduce),
    ("__copy__", _copy),
    ("__deepcopy__", _deepcopy),
    ("segment_nu", property(_segment_nu, doc=DOCS["SolveResult.segment_nu"])),
    ("contact_outcome", property(_contact_outcome, doc=DOCS["SolveResult.contact_outcome"])),
]:
    setattr(SolveResult, _name, _value)
