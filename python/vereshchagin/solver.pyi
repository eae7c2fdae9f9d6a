from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core

@dataclass(frozen=True)
class BatchResult:
    qdd: NDArray[np.float64]
    tau_command: NDArray[np.float64]
    nu: NDArray[np.float64]
    link_acc: NDArray[np.float64]
    constraint_rank: NDArray[np.int32]
    smallest_singular_value: NDArray[np.float64]

class Solver(_core.Solver):
    def solve_batch(  # type: ignore[override]
        self,
        q: ArrayLike,
        qd: ArrayLike,
        alpha: Optional[ArrayLike] = None,
        beta: Optional[ArrayLike] = None,
        f_ext: Optional[ArrayLike] = None,
        tau_ff: Optional[ArrayLike] = None,
    ) -> BatchResult: ...
    def response_columns(
        self, joints: Sequence[int]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
