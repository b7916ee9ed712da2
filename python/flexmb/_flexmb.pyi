"""Type stubs of the extension module flexmb._flexmb (see flexmb/__init__.py)."""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, "os.PathLike[str]"]
_Floats = Union[Sequence[float], npt.NDArray[np.floating]]
_Progress = Union[None, bool, Callable[[float], Any]]
_F1 = npt.NDArray[np.float64]

class FlexmbError(Exception):
    """Base class of every error flexmb raises; the message names the culprit."""

class SceneError(FlexmbError):
    """A scene (file, text or dict) that cannot be read."""

class ModelError(FlexmbError):
    """A scene that reads but is no valid mechanism, or a reduced model that does not fit."""

class SolverError(FlexmbError):
    """A computation on a valid model failed."""

class ArgumentError(FlexmbError):
    """An argument out of range or of the wrong kind."""

class Scene:
    """A scene: nodes, materials, sections, elements, roles, loads, outputs."""
    @staticmethod
    def load(path: _Path) -> Scene:
        """Reads a scene file (RON)."""
    @staticmethod
    def from_str(text: str, base_dir: Optional[_Path] = None) -> Scene:
        """Parses a scene from RON text."""
    @staticmethod
    def from_dict(d: Dict[str, Any], base_dir: Optional[_Path] = None) -> Scene:
        """Builds a scene from dicts, lists, strings and numbers (strict: unknown fields are errors)."""
    def to_ron(self) -> str:
        """The scene as RON text."""
    def to_dict(self) -> Dict[str, Any]:
        """The scene as Python data, in the form from_dict reads."""
    @property
    def name(self) -> str: ...

class StaticResult:
    """A static equilibrium."""
    q: _F1
    x: _F1
    positions: _F1
    displacements: _F1
    deformations: _F1
    node_ids: List[str]
    deformation_names: List[str]
    iterations: int
    increments: int

class EigResult:
    """Undamped modes: frequencies (k,), mode_shapes (k, n_nodes, dim), nodal (k, n_x), vectors (k, n_dof)."""
    frequencies: _F1
    mode_shapes: _F1
    nodal: _F1
    vectors: _F1
    node_ids: List[str]
    damped_frequencies: Optional[_F1]
    damping_ratios: Optional[_F1]

class SweepResult:
    """Eigenfrequencies along a sweep: values (n,), frequencies (n, k)."""
    values: _F1
    frequencies: _F1
    holding: _F1
    held: List[str]
    stopped: bool

class SimulationResult:
    """A time response: t (n,), q and qd (n, n_dof), the scene's outputs, evaluation counts."""
    t: _F1
    q: _F1
    qd: _F1
    coordinates: _F1
    outputs: Dict[str, _F1]
    output_names: List[str]
    stats: Dict[str, int]
    wall_time: float
    stopped: bool
    @property
    def rhs_evals(self) -> int:
        """The number of function evaluations."""

class SuperelementResult:
    """What build_superelement built."""
    summary: str
    written: List[str]
    normal_frequencies: _F1
    l0: float
    n_modes: int

class Model:
    """A mechanism with all its degrees of freedom."""
    def __init__(self, scene: Scene) -> None: ...
    def info(self) -> Dict[str, Any]:
        """Name, summary, counts and the names of DOFs, inputs, nodes, coordinates, deformations."""
    def static(self, t: float = 0.0, steps: int = 1) -> StaticResult:
        """The static equilibrium under the loads and gravity at time t."""
    def eig(self, k: Optional[int] = None, static_first: bool = False) -> EigResult:
        """The k lowest undamped eigenfrequencies and mode shapes."""
    def sweep(
        self,
        over: str = "load",
        values: Optional[_Floats] = None,
        modes: Optional[int] = None,
        t_load: float = 0.0,
        progress: _Progress = None,
    ) -> SweepResult:
        """Eigenfrequencies at the static equilibria along a load scale or a held DOF."""
    def simulate(
        self,
        t_end: float = 1.0,
        outputs: int = 501,
        integrator: str = "dopri5",
        rtol: float = 1e-3,
        atol: float = 1e-6,
        static_first: bool = False,
        progress: _Progress = None,
    ) -> SimulationResult:
        """The time response (interruptible with Ctrl-C)."""
    def reduce(
        self,
        method: str,
        modes: int,
        keep: Optional[Sequence[str]] = None,
        a: Optional[float] = None,
        threshold: Optional[float] = None,
        final_threshold: Optional[float] = None,
        over: Optional[str] = None,
        values: Optional[_Floats] = None,
        t_load: float = 0.0,
        no_gravity: bool = False,
        progress: _Progress = None,
    ) -> ReducedModel:
        """A reduced model (modal, svd-modal, fbm-svd, ibm-msi, ibm-mac)."""
    def load_reduced(self, path: _Path) -> ReducedModel:
        """A reduced model saved by flexmb reduce or ReducedModel.save."""

class ReducedModel:
    """A reduced model q = G(z)."""
    @property
    def n_z(self) -> int: ...
    @property
    def description(self) -> str: ...
    @property
    def interpolated(self) -> bool: ...
    def info(self) -> Dict[str, Any]: ...
    def save(self, path: _Path) -> None:
        """Writes the model for flexmb simulate --reduced."""
    def eig(self, k: Optional[int] = None) -> _F1:
        """Reduced eigenfrequencies (Hz) at the reference coordinates."""
    def simulate(
        self,
        t_end: float = 1.0,
        outputs: int = 501,
        integrator: str = "dopri5",
        rtol: float = 1e-3,
        atol: float = 1e-6,
        static_first: bool = False,
        progress: _Progress = None,
    ) -> SimulationResult: ...
    def sweep(
        self,
        values: _Floats,
        over: str = "load",
        modes: Optional[int] = None,
        t_load: float = 0.0,
        progress: _Progress = None,
    ) -> SweepResult: ...

def build_superelement(spec: _Path, output: Optional[_Path] = None) -> SuperelementResult:
    """Builds a linear superelement from FE matrices (as flexmb build-superelement)."""
