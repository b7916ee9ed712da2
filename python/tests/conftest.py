"""Shared fixtures: the repository root, the scenes, and the CLI binary
(FLEXMB_BIN, default target/release/flexmb) whose numbers the bindings must
reproduce."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "fixtures" / "scenes"


def scene_path(name: str) -> Path:
    """The fixture scene `name` (without .ron)."""
    return SCENES / f"{name}.ron"


@pytest.fixture(scope="session")
def flexmb_bin() -> Path:
    """The CLI binary; a missing one fails the tests that need it."""
    p = Path(os.environ.get("FLEXMB_BIN", ROOT / "target" / "release" / "flexmb"))
    if not p.is_absolute():
        p = ROOT / p
    assert p.is_file(), f"the flexmb CLI is needed at {p} (set FLEXMB_BIN; build it with cargo build --release -p flexmb-cli)"
    return p


@pytest.fixture(scope="session")
def cli_run(flexmb_bin: Path):
    """Runs the CLI with arguments, returning the completed process."""

    def run(*args: object) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(flexmb_bin), *map(str, args)],
            capture_output=True,
            text=True,
            cwd=ROOT,
            timeout=600,
        )

    return run


@pytest.fixture(scope="session")
def cli(cli_run):
    """Runs the CLI with arguments, returning its stdout; fails on a non-zero exit."""

    def run(*args: object) -> str:
        r = cli_run(*args)
        assert r.returncode == 0, f"flexmb {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}"
        return r.stdout

    return run


def read_csv(path: Path):
    """(comments, header, rows) of a CSV written by flexmb (write_csv)."""
    import numpy as np

    comments, header, rows = [], None, []
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            comments.append(line[1:].strip())
        elif not line.strip():
            continue
        elif header is None:
            header = [h.strip() for h in line.split(",")]
        else:
            rows.append([float(v) for v in line.split(",")])
    return comments, header, np.array(rows)
