from dataclasses import dataclass
from typing import Mapping, Optional, Sequence, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from .contacts import Contact

@dataclass(frozen=True)
class BatchResult:
    qdd: NDArray[np.float64]
    tau_command: NDArray[np.float64]
    nu: NDArray[np.float64]
    link_acc: NDArray[np.float64]
    constraint_rank: NDArray[np.int32]
    smallest_singular_value: NDArray[np.float64]
    friction_torque: Optional[NDArray[np.float64]] = None
    limit_torque: Optional[NDArray[np.float64]] = None
    status: Optional[NDArray[np.int32]] = None
    gauss_value: Optional[NDArray[np.float64]] = None
    iterations: Optional[NDArray[np.int32]] = None
    segment_nu: Optional[dict] = None
    contact_force: Optional[NDArray[np.float64]] = None
    contact_status: Optional[NDArray[np.int32]] = None
    contact_outcome: Optional[NDArray[np.int32]] = None

class Solver(_core.Solver):
    def __init__(
        self,
        model: Union[_core.Chain, _core.Tree],
        gravity: ArrayLike = ...,
        rcond: float = 1e-12,
        damping: Optional[float] = None,
        inertia_check: Optional[str] = None,
        max_constraints: Optional[int] = None,
    ) -> None: ...
    def solve_batch(  # type: ignore[override]
        self,
        q: ArrayLike,
        qd: ArrayLike,
        alpha: Optional[ArrayLike] = None,
        beta: Optional[ArrayLike] = None,
        f_ext: Optional[ArrayLike] = None,
        tau_ff: Optional[ArrayLike] = None,
        friction: object = None,
        constraints: Optional[Mapping[Union[str, int], tuple[ArrayLike, ArrayLike]]] = None,
        f_ext_pass_through: Optional[ArrayLike] = None,
        tau_ff_pass_through: Optional[ArrayLike] = None,
        threads: int = 1,
        a_desired: Optional[ArrayLike] = None,
        contacts: Optional[Sequence[Contact]] = None,
        time_step: Optional[float] = None,
        contact_velocity_tolerance: Optional[float] = None,
        contact_max_pivots: Optional[int] = None,
    ) -> BatchResult: ...
    @property
    def chain(self) -> _core.Chain: ...
    @property
    def tree(self) -> _core.Tree: ...
    def __reduce__(self) -> tuple: ...
    def response_columns(  # type: ignore[override]
        self, joints: Sequence[Union[int, str]], hold_sticking: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
