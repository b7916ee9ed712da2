"""flexmb: flexible multibody dynamics and model reduction for compliant
mechanisms (after S.E. Boer's thesis), from Python, with numpy arrays.

A scene (``Scene.load(path)``, ``Scene.from_str(text)`` or
``Scene.from_dict(d)``) becomes a ``Model``; its ``static``, ``eig``,
``sweep`` and ``simulate`` give the numbers of the command line ``flexmb``
as numpy arrays, and ``reduce`` gives a ``ReducedModel`` that simulates and
sweeps the same way. ``build_superelement(spec)`` builds a superelement from
FE matrices.

Every error is a ``FlexmbError`` (``SceneError``, ``ModelError``,
``SolverError``, ``ArgumentError``) carrying flexmb's message. The long runs
release the GIL, stop on Ctrl-C (the ``KeyboardInterrupt`` carries the
partial result as its ``partial`` attribute) and take ``progress=True``
(a tqdm bar, if tqdm is installed) or a callable.
"""

from ._flexmb import (
    ArgumentError,
    EigResult,
    FlexmbError,
    Model,
    ModelError,
    ReducedModel,
    Scene,
    SceneError,
    SimulationResult,
    SolverError,
    StaticResult,
    SuperelementResult,
    SweepResult,
    __version__,
    build_superelement,
)

__all__ = [
    "ArgumentError",
    "EigResult",
    "FlexmbError",
    "Model",
    "ModelError",
    "ReducedModel",
    "Scene",
    "SceneError",
    "SimulationResult",
    "SolverError",
    "StaticResult",
    "SuperelementResult",
    "SweepResult",
    "__version__",
    "build_superelement",
]
