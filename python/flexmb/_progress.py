"""Progress displays for the long runs (simulate, sweep, reduce)."""

from __future__ import annotations

from typing import Any, Callable, Optional


class _Callback:
    """Calls ``fn(fraction)`` when the fraction done changes."""

    def __init__(self, fn: Callable[[float], Any]) -> None:
        self._fn = fn
        self._last = -1.0

    def update(self, fraction: float) -> None:
        if fraction != self._last:
            self._last = fraction
            self._fn(fraction)

    def close(self) -> None:
        pass


class _Tqdm:
    """A tqdm bar over 1000 steps of the fraction done."""

    def __init__(self, tqdm: Any, what: str) -> None:
        self._bar = tqdm(total=1000, desc=what, unit="‰", leave=False)
        self._n = 0

    def update(self, fraction: float) -> None:
        n = int(1000 * fraction)
        if n > self._n:
            self._bar.update(n - self._n)
            self._n = n

    def close(self) -> None:
        self._bar.close()


def make(progress: Any, what: str) -> Optional[object]:
    """The display for a ``progress=`` argument: None or False for none,
    True for a tqdm bar (none if tqdm is not installed), or a callable taking
    the fraction done in [0, 1]."""
    if progress is None or progress is False:
        return None
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return None
        return _Tqdm(tqdm, what)
    if callable(progress):
        return _Callback(progress)
    raise TypeError(
        f"progress must be None, a bool or a callable taking the fraction done; got {type(progress).__name__}"
    )
