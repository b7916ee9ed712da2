"""Long runs release the GIL, stop promptly on SIGINT (KeyboardInterrupt
with the partial result attached) and report progress."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

import flexmb
from conftest import scene_path

# a run of far more than a minute: the spatial guidance at tight tolerances
LONG = dict(t_end=1000.0, outputs=100001, rtol=1e-10, atol=1e-12)


@pytest.fixture(scope="module")
def guidance():
    return flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_spatial")))


def sigint_after(delay: float) -> threading.Timer:
    """Sends SIGINT to this process from another thread after `delay` s."""
    t = threading.Timer(delay, lambda: os.kill(os.getpid(), signal.SIGINT))
    t.start()
    return t


def test_sigint_stops_a_long_simulation_quickly(guidance):
    timer = sigint_after(1.0)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt) as info:
        guidance.simulate(**LONG)
    elapsed = time.monotonic() - start
    timer.join()
    # the signal came after 1 s; the run stops within a step of it
    assert elapsed < 3.0, f"stopped {elapsed:.2f} s after the start"
    partial = info.value.partial
    assert isinstance(partial, flexmb.SimulationResult)
    assert partial.stopped
    assert 0.0 < partial.t[-1] < LONG["t_end"]
    assert partial.q.shape[0] == len(partial.t)
    assert partial.rhs_evals > 0


def test_sigint_stops_a_sweep_with_the_points_done():
    model = flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_spatial")))
    timer = sigint_after(0.5)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt) as info:
        model.sweep(over="load", values=[0.001 * i for i in range(5000)], modes=4, t_load=0.05)
    timer.join()
    assert time.monotonic() - start < 3.0
    partial = info.value.partial
    assert isinstance(partial, flexmb.SweepResult) and partial.stopped
    assert partial.frequencies.shape[0] < 5000


def test_the_gil_is_released_during_a_run():
    model = flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_planar")))
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    th = threading.Thread(target=count)
    th.start()
    start = time.monotonic()
    r = model.simulate(t_end=0.5, outputs=11, rtol=1e-6, atol=1e-9)
    end = time.monotonic()
    done.set()
    th.join()
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.2, "the run is too short to tell"
    # the other thread kept running: a tick at least every 50 ms on average
    assert len(during) > (end - start) / 0.05, (len(during), end - start)
    assert r.rhs_evals > 0


def test_progress_callback_sees_the_run_advance():
    model = flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_planar")))
    seen = []
    model.simulate(t_end=0.3, outputs=31, rtol=1e-6, atol=1e-9, progress=seen.append)
    assert seen, "the progress callback was never called"
    assert seen == sorted(seen)
    assert seen[-1] == pytest.approx(1.0)
    assert all(0.0 <= f <= 1.0 for f in seen)


def test_failing_progress_callback_stops_the_run():
    model = flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_planar")))
    seen = []

    def boom(fraction):
        seen.append(fraction)
        if fraction > 0:
            raise RuntimeError("stop here")

    start = time.monotonic()
    with pytest.raises(RuntimeError, match="stop here"):
        # progress is reported at the output times: many of them
        model.simulate(t_end=1000.0, outputs=1000001, progress=boom)
    assert time.monotonic() - start < 5.0
    assert seen[-1] < 0.01


def test_progress_true_without_or_with_tqdm(guidance):
    r = flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_planar"))).simulate(
        t_end=0.05, outputs=6, progress=True
    )
    assert len(r.t) == 6
    with pytest.raises(TypeError, match="progress must be"):
        guidance.simulate(t_end=0.01, progress="yes")
