"""Type stubs of the compiled module vereshchagin._core."""
from typing import Optional, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

class SolverError(ValueError): ...

class Joint:
    @staticmethod
    def revolute(axis: ArrayLike, origin: Optional[ArrayLike] = None) -> Joint: ...
    @staticmethod
    def prismatic(axis: ArrayLike, origin: Optional[ArrayLike] = None) -> Joint: ...
    @staticmethod
    def fixed() -> Joint: ...

class Chain:
    def __init__(self) -> None: ...
    def add_segment(
        self,
        name: str,
        joint: str | Joint,
        tip: Optional[ArrayLike] = None,
        mass: float = 0.0,
        com: Optional[ArrayLike] = None,
        inertia: Optional[ArrayLike] = None,
        rotor_inertia: float = 0.0,
        joint_name: str = "",
    ) -> None: ...
    @property
    def n_joints(self) -> int: ...
    @property
    def n_segments(self) -> int: ...
    @property
    def segment_names(self) -> list[str]: ...
    @property
    def joint_names(self) -> list[str]: ...

class SolveResult:
    @property
    def qdd(self) -> NDArray[np.float64]: ...
    @property
    def tau_command(self) -> NDArray[np.float64]: ...
    @property
    def nu(self) -> NDArray[np.float64]: ...
    @property
    def link_acc(self) -> NDArray[np.float64]: ...
    @property
    def constraint_rank(self) -> int: ...
    @property
    def smallest_singular_value(self) -> float: ...

class Solver:
    def __init__(
        self,
        chain: Chain,
        gravity: ArrayLike = ...,
        rcond: float = 1e-12,
        damping: Optional[float] = None,
    ) -> None: ...
    def solve(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        alpha: Optional[ArrayLike] = None,
        beta: Optional[ArrayLike] = None,
        f_ext: Optional[ArrayLike] = None,
        tau_ff: Optional[ArrayLike] = None,
    ) -> SolveResult: ...
    def solve_batch(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        alpha: Optional[ArrayLike] = None,
        beta: Optional[ArrayLike] = None,
        f_ext: Optional[ArrayLike] = None,
        tau_ff: Optional[ArrayLike] = None,
    ) -> dict: ...
    def response_columns(
        self, joints: Sequence[int]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    gravity: NDArray[np.float64]
    @property
    def n_joints(self) -> int: ...
    @property
    def n_segments(self) -> int: ...
