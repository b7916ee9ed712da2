"""Bad input raises the right exception, with the culprit named."""

from __future__ import annotations

import numpy as np
import pytest

import flexmb
from conftest import scene_path

GOOD = dict(
    dimension="Planar",
    materials={"al": {"e": 7.0e10, "rho": 2700.0}},
    sections={"bar": {"Rectangle": {"by": 0.01, "bz": 0.02}}},
    nodes=[{"id": "A", "at": [0.0, 0.0]}, {"id": "B", "at": [1.0, 0.0]}],
    elements=[{"id": "arm", "type": {"Beam": {"nodes": ["A", "B"], "material": "al", "section": "bar", "n": 4}}}],
    fixed=[{"Coord": ["A", "Position"]}],
    rigid=[{"Def": ["arm", "elongation"]}],
)


def good(**changes):
    d = {k: v for k, v in GOOD.items()}
    d.update(changes)
    return d


@pytest.fixture(scope="module")
def guidance():
    return flexmb.Model(flexmb.Scene.load(scene_path("straight_guidance_planar")))


def test_the_dict_scene_builds_like_the_ron_one():
    m = flexmb.Model(flexmb.Scene.from_dict(good()))
    # a pinned arm of 4 beams: the rotation at A plus 2 bending deformations per beam
    assert m.info()["n_dof"] == 9
    ron = flexmb.Scene.from_dict(good()).to_ron()
    assert flexmb.Model(flexmb.Scene.from_str(ron)).info() == m.info()


def test_exception_hierarchy():
    for e in (flexmb.SceneError, flexmb.ModelError, flexmb.SolverError, flexmb.ArgumentError):
        assert issubclass(e, flexmb.FlexmbError)
        assert issubclass(e, Exception)


def test_missing_file_names_it(tmp_path):
    p = tmp_path / "nope.ron"
    with pytest.raises(flexmb.SceneError, match="nope.ron"):
        flexmb.Scene.load(p)


def test_syntax_error_has_line_and_column():
    with pytest.raises(flexmb.SceneError, match=r"line 2, column \d+"):
        flexmb.Scene.from_str("(\n  nodes: [}, elements: [],\n)")


def test_unknown_field_in_text_suggests_the_nearest():
    with pytest.raises(flexmb.SceneError, match="did you mean `gravity`"):
        flexmb.Scene.from_str("(nodes: [], elements: [], gravityy: Some([0.0, -9.81]))")


def test_unknown_top_level_dict_field_is_an_error():
    with pytest.raises(flexmb.SceneError, match=r"gravityy.*did you mean `gravity`"):
        flexmb.Scene.from_dict(good(gravityy=[0.0, -9.81]))


def test_unknown_nested_dict_field_names_its_path():
    d = good()
    d["elements"] = [{"id": "arm", "type": {"Beam": {"nodes": ["A", "B"], "material": "al", "section": "bar", "nn": 4}}}]
    with pytest.raises(flexmb.SceneError, match=r"elements\[0\]\.type.*unknown field `nn`.*did you mean `n`"):
        flexmb.Scene.from_dict(d)


def test_unknown_variant_in_dict_is_an_error():
    d = good()
    d["elements"] = [{"id": "arm", "type": {"Bean": {"nodes": ["A", "B"], "material": "al", "section": "bar"}}}]
    with pytest.raises(flexmb.SceneError, match=r"elements\[0\]\.type.*`Bean`.*did you mean `Beam`"):
        flexmb.Scene.from_dict(d)


def test_wrong_kind_of_value_in_dict():
    with pytest.raises(flexmb.SceneError, match=r"nodes\[1\]\.at"):
        flexmb.Scene.from_dict(good(nodes=[{"id": "A", "at": [0.0, 0.0]}, {"id": "B", "at": "far"}]))
    with pytest.raises(flexmb.SceneError, match=r"nodes\[1\]\.at\[0\].*not a finite number"):
        flexmb.Scene.from_dict(good(nodes=[{"id": "A", "at": [0.0, 0.0]}, {"id": "B", "at": [float("nan"), 0.0]}]))
    with pytest.raises(flexmb.SceneError, match=r"scene\.nodes.*set is no scene value"):
        flexmb.Scene.from_dict(good(nodes={1, 2}))


def test_numpy_values_are_accepted_in_dicts():
    d = good(nodes=[{"id": "A", "at": np.zeros(2)}, {"id": "B", "at": np.array([1.0, 0.0])}])
    assert flexmb.Model(flexmb.Scene.from_dict(d)).info()["n_dof"] == 9


def test_unknown_node_is_a_model_error_naming_it():
    d = good(fixed=[{"Coord": ["Q", "Position"]}])
    with pytest.raises(flexmb.ModelError, match="'Q'"):
        flexmb.Model(flexmb.Scene.from_dict(d))


def test_under_constrained_mechanism_is_a_model_error():
    with pytest.raises(flexmb.ModelError):
        flexmb.Model(flexmb.Scene.from_dict(good(fixed=[], dofs={"Explicit": []})))


@pytest.mark.parametrize(
    "call,match",
    [
        (lambda m: m.simulate(t_end=-1.0), "t_end must be positive"),
        (lambda m: m.simulate(t_end=0.1, outputs=1), "outputs must be at least 2"),
        (lambda m: m.simulate(t_end=0.1, integrator="rk4"), "unknown integrator 'rk4'"),
        (lambda m: m.simulate(t_end=0.1, rtol=0.0), "rtol must be positive"),
        (lambda m: m.eig(0), "at least 1"),
        (lambda m: m.eig(1000), "at most 17 modes"),
        (lambda m: m.static(steps=0), "steps must be at least 1"),
        (lambda m: m.sweep(over="load", values=[1.0]), "at least 2 values"),
        (lambda m: m.sweep(over="Q.x", values=[0.0, 1.0]), "unknown coordinate 'Q.x'"),
        (lambda m: m.sweep(over="load", values=[0.0, float("inf")]), r"values\[1\] is inf"),
        (lambda m: m.reduce(method="pod", modes=2), "unknown method 'pod'"),
        (lambda m: m.reduce(method="modal", modes=0), "modes must be at least 1"),
        (lambda m: m.reduce(method="ibm-msi", modes=2, over="load", values=[0, 1, 2]), "over=COORD"),
        (lambda m: m.reduce(method="svd-modal", modes=2), "builds its basis from a sweep"),
        (lambda m: m.reduce(method="modal", modes=2, a=1.0), "a \\(svd-modal only\\)"),
        (lambda m: m.reduce(method="modal", modes=2, keep=["nope"]), "unknown coordinate 'nope'"),
    ],
)
def test_bad_arguments_are_argument_errors(guidance, call, match):
    with pytest.raises(flexmb.ArgumentError, match=match):
        call(guidance)


def test_reduced_model_rejects_implicit_integrator_and_coordinate_sweeps(guidance):
    red = guidance.reduce(method="modal", modes=2)
    with pytest.raises(flexmb.ArgumentError, match="explicit integrator"):
        red.simulate(t_end=0.1, integrator="genalpha")
    with pytest.raises(flexmb.ArgumentError, match='"load" only'):
        red.sweep(values=[0.0, 1.0], over="S.x")


def test_reduced_model_of_other_dofs_is_a_model_error(guidance, tmp_path):
    p = tmp_path / "m.ron"
    guidance.reduce(method="modal", modes=2).save(p)
    other = flexmb.Model(flexmb.Scene.from_dict(good()))
    with pytest.raises(flexmb.ModelError):
        other.load_reduced(p)


def test_no_equilibrium_is_a_solver_error():
    """A column under a load far beyond anything one Newton solve with a
    single, never-halved increment reaches: the static solver gives up."""
    d = good(
        nodes=[{"id": "A", "at": [0.0, 0.0]}, {"id": "B", "at": [1.0, 0.0]}],
        rigid=[],
        loads=[{"node": "B", "force": [0.0, 1.0e12]}],
    )
    with pytest.raises(flexmb.SolverError):
        flexmb.Model(flexmb.Scene.from_dict(d)).static()
