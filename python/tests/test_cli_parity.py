"""The bindings give the numbers of the CLI binary on the fixture scenes:
static equilibria, eigenfrequencies, simulations (exact evaluation counts),
sweeps and reduced models."""

from __future__ import annotations

import re

import numpy as np
import pytest

import flexmb
from conftest import ROOT, read_csv, scene_path

from conftest import SCENES

# every fixture scene, read, built and analysed by both
ALL_SCENES = sorted(p.stem for p in SCENES.glob("*.ron"))


def cli_or_same_failure(cli_run, *args):
    """The CLI's stdout, or None if it failed to compute (exit code 1), in
    which case the bindings must raise SolverError with the same message."""
    r = cli_run(*args)
    if r.returncode == 1:
        return None, r.stderr.strip().removeprefix("error: ")
    assert r.returncode == 0, f"flexmb {args} failed ({r.returncode}): {r.stderr}"
    return r.stdout, None


def model(name: str) -> flexmb.Model:
    return flexmb.Model(flexmb.Scene.load(scene_path(name)))


def test_every_fixture_scene_is_covered():
    assert len(ALL_SCENES) >= 10


@pytest.mark.parametrize("name", ALL_SCENES)
def test_static_matches_cli(name, cli_run, tmp_path):
    text, failure = cli_or_same_failure(cli_run, "static", scene_path(name), "--out", tmp_path)
    if failure is not None:
        # a free body or a pendulum released sideways has no equilibrium
        with pytest.raises(flexmb.SolverError) as info:
            model(name).static()
        assert str(info.value) == failure
        return
    _, header, pos = read_csv(tmp_path / "node_positions.csv")
    _, _, eps = read_csv(tmp_path / "deformations.csv")
    st = model(name).static()
    assert st.positions.shape == pos.shape and len(header) == pos.shape[1]
    # the CSV holds 13 significant digits
    np.testing.assert_allclose(st.positions, pos, rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(st.deformations, eps[:, 0], rtol=1e-11, atol=1e-13)
    # the displacements the CLI prints, 7 significant digits
    printed = {}
    for line in text.splitlines():
        m = re.match(r"^\s+(\S+)\s+displacement \[(.*)\]$", line)
        if m:
            printed[m.group(1)] = [float(v) for v in m.group(2).split(",")]
    assert list(printed) == st.node_ids
    np.testing.assert_allclose(st.displacements, np.array(list(printed.values())), rtol=1e-6, atol=1e-15)


def cli_frequencies(text: str) -> np.ndarray:
    """The undamped eigenfrequencies `flexmb eig` prints."""
    block = text.split("undamped eigenfrequencies (Hz)")[1].splitlines()[1:]
    out = []
    for line in block:
        m = re.match(r"^\s+(\d+)\s+(\S+)\s*$", line)
        if not m:
            break
        out.append(float(m.group(2)))
    return np.array(out)


@pytest.mark.parametrize("name", ALL_SCENES)
@pytest.mark.parametrize("static_first", [False, True])
def test_eig_matches_cli(name, static_first, cli_run):
    # four modes, or all of a scene with fewer DOFs (the ch4 skeleton has 3)
    k = min(4, len(model(name).info()["dofs"]))
    args = ["eig", scene_path(name), "--modes", k]
    if static_first:
        args.append("--static-first")
    text, failure = cli_or_same_failure(cli_run, *args)
    if failure is not None:
        with pytest.raises(flexmb.SolverError) as info:
            model(name).eig(k, static_first=static_first)
        assert str(info.value) == failure
        return
    f_cli = cli_frequencies(text)
    e = model(name).eig(k, static_first=static_first)
    assert len(f_cli) == k
    # printed with 6 decimals
    np.testing.assert_allclose(e.frequencies, f_cli, rtol=0, atol=6e-7)
    # mode shapes: one per frequency, at every node
    assert e.mode_shapes.shape[0] == k
    assert e.mode_shapes.shape[1] == len(e.node_ids)


def cli_evaluations(comments) -> int:
    for c in comments:
        m = re.search(r"(\d+) function evaluations", c)
        if m:
            return int(m.group(1))
    raise AssertionError(f"no evaluation count in {comments}")


@pytest.mark.parametrize(
    "name,t_end,integrator",
    [
        ("straight_guidance_planar", 0.05, "dopri5"),
        ("flexible_pendulum", 0.5, "adams"),
        ("manipulator_planar", 0.2, "dopri5"),
        ("straight_guidance_planar", 0.02, "genalpha"),
    ],
)
def test_simulate_matches_cli(name, t_end, integrator, cli, tmp_path):
    cli("simulate", scene_path(name), "--t-end", t_end, "--outputs", 21,
        "--integrator", integrator, "--out", tmp_path)
    comments, header, rows = read_csv(tmp_path / "outputs.csv")
    r = model(name).simulate(t_end=t_end, outputs=21, integrator=integrator)
    assert r.rhs_evals == cli_evaluations(comments)
    assert r.stats["rhs_evals"] == r.rhs_evals
    assert header == ["t"] + r.output_names
    np.testing.assert_allclose(r.t, rows[:, 0], rtol=1e-12, atol=1e-14)
    for k, h in enumerate(r.output_names):
        np.testing.assert_allclose(r.outputs[h], rows[:, k + 1], rtol=1e-10, atol=1e-12, err_msg=h)
    assert r.q.shape == (21, model(name).info()["n_dof"])
    assert not r.stopped


def test_sweep_matches_cli(cli, tmp_path):
    name = "straight_guidance_planar"
    cli("sweep", scene_path(name), "--over", "load", "--from", 0, "--to", 1,
        "--n", 5, "--modes", 3, "--out", tmp_path)
    _, header, rows = read_csv(tmp_path / "eigenfrequencies.csv")
    s = model(name).sweep(over="load", values=np.linspace(0, 1, 5), modes=3)
    assert header[:4] == ["load_scale", "f1_hz", "f2_hz", "f3_hz"]
    assert s.frequencies.shape == (5, 3)
    np.testing.assert_allclose(s.values, rows[:, 0], rtol=1e-12)
    np.testing.assert_allclose(s.frequencies, rows[:, 1:4], rtol=1e-10)


def test_reduced_model_matches_cli(cli, tmp_path):
    """A modal reduced model made in Python and one made by `flexmb reduce`
    have the same frequencies, and the CLI integrates the Python-saved model
    with exactly the evaluations of the Python run."""
    name = "straight_guidance_planar"
    m = model(name)
    red = m.reduce(method="modal", modes=3)
    assert red.n_z == 3
    saved = tmp_path / "modal3.ron"
    red.save(saved)
    cli_model = tmp_path / "cli_modal3.ron"
    cli("reduce", scene_path(name), "--method", "modal", "--modes", 3, "--out", cli_model)
    _, _, freqs = read_csv(tmp_path / "cli_modal3.frequencies.csv")
    np.testing.assert_allclose(red.eig(), freqs[:, 1], rtol=1e-10)
    # the CLI's model, loaded in Python, is the same model
    np.testing.assert_allclose(m.load_reduced(cli_model).eig(), red.eig(), rtol=1e-12)

    out = tmp_path / "sim"
    cli("simulate", scene_path(name), "--reduced", saved, "--t-end", 0.1, "--outputs", 11, "--out", out)
    comments, header, rows = read_csv(out / "outputs.csv")
    r = red.simulate(t_end=0.1, outputs=11)
    assert r.rhs_evals == cli_evaluations(comments)
    for k, h in enumerate(r.output_names):
        np.testing.assert_allclose(r.outputs[h], rows[:, k + 1], rtol=1e-10, atol=1e-12, err_msg=h)
    # and the reduced model needs fewer evaluations than the unreduced one
    assert r.rhs_evals < m.simulate(t_end=0.1, outputs=11).rhs_evals

    out = tmp_path / "sweep"
    cli("sweep", scene_path(name), "--reduced", saved, "--over", "load", "--from", 0,
        "--to", 1, "--n", 3, "--modes", 3, "--out", out)
    _, _, rows = read_csv(out / "eigenfrequencies.csv")
    s = red.sweep(values=[0.0, 0.5, 1.0], modes=3)
    np.testing.assert_allclose(s.frequencies, rows[:, 1:4], rtol=1e-10)


def test_build_superelement_matches_cli(cli, tmp_path):
    spec = ROOT / "fixtures" / "fe-exports" / "rotor_abaqus.spec.ron"
    text = cli("build-superelement", spec)
    r = flexmb.build_superelement(spec, output=tmp_path / "rotor.se.ron")
    assert r.written[0] == str(tmp_path / "rotor.se.ron")
    assert (tmp_path / "rotor.se.ron").is_file()
    line = next(l for l in text.splitlines() if l.startswith("fixed-interface normal modes"))
    cli_hz = [float(v) for v in line.split(":")[1].replace("Hz", "").split(",")]
    np.testing.assert_allclose(r.normal_frequencies, cli_hz, rtol=0, atol=6e-5)
    assert r.summary.splitlines()[0] == text.splitlines()[0]
    assert f"{12 + r.n_modes} coordinates" in r.summary.splitlines()[0]


def cli_linspace(lo: float, hi: float, n: int) -> list:
    """The sweep values of the CLI's --from/--to/--n, to the last bit."""
    return [lo + (hi - lo) * i / (n - 1) for i in range(n)]


def nodal_guidance() -> flexmb.Scene:
    """The planar guidance with nodal DOFs and S.x first (docs/cli.md), made
    by editing the scene's dict."""
    d = flexmb.Scene.load(scene_path("straight_guidance_planar")).to_dict()
    d["dofs"] = "NodalCoordinates"
    d["dofs_first"] = [{"Coord": ["S", "X"]}]
    return flexmb.Scene.from_dict(d)


@pytest.mark.parametrize(
    "method,modes,over,lo,hi,n,t_load",
    [
        ("svd-modal", 3, "load", -1.0, 1.0, 10, 0.05),
        ("fbm-svd", 3, "load", -1.0, 1.0, 10, 0.05),
        ("ibm-msi", 1, "S.x", -0.0834, 0.0834, 41, 0.0),
        ("ibm-mac", 2, "S.x", -0.0834, 0.0834, 41, 0.0),
    ],
)
def test_sweep_reductions_match_cli(method, modes, over, lo, hi, n, t_load, cli, tmp_path):
    scene = nodal_guidance() if method.startswith("ibm") else flexmb.Scene.load(scene_path("straight_guidance_planar"))
    scene_file = tmp_path / "scene.ron"
    scene_file.write_text(scene.to_ron())
    cli_model = tmp_path / "cli.ron"
    cli("reduce", scene_file, "--method", method, "--modes", modes, "--over", over,
        "--from", lo, "--to", hi, "--n", n, "--t-load", t_load, "--out", cli_model)
    _, _, freqs = read_csv(tmp_path / "cli.frequencies.csv")
    m = flexmb.Model(scene)
    red = m.reduce(method=method, modes=modes, over=over, values=cli_linspace(lo, hi, n), t_load=t_load)
    theirs = m.load_reduced(cli_model)
    assert red.n_z == theirs.n_z == len(freqs)
    assert red.description == theirs.description
    assert red.interpolated == method.startswith("ibm")
    np.testing.assert_allclose(red.eig(), freqs[:, 1], rtol=1e-10)
    a = red.simulate(t_end=0.05, outputs=6)
    b = theirs.simulate(t_end=0.05, outputs=6)
    assert a.rhs_evals == b.rhs_evals
    np.testing.assert_allclose(a.q, b.q, rtol=1e-10, atol=1e-13)
