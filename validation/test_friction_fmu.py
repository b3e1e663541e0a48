"""Issue 25's must-show "in the FMU under fmpy, a friction damper's force–displacement loop equals
the CLI's": fmu/scenes/friction-damper.toml (a Jenkins damper, stick–slip, bds1, k = 256) packaged
and run with fmpy.simulate_fmu over one period at the k instants. Its outputs friction[0].force,
friction[0].slip_velocity, friction[0].stuck and displacement[0] (the damper slides along DOF 0,
so the loop's abscissa) equal the CLI's JSON friction entry to 1e-9 of each series' range; the
tunable normal_force_scale = 0.5 equals the CLI on the scene with its normal load halved in the
text. Cheap (three CLI runs, two short simulations).
"""
import json
import os

import fmpy
from fmpy.validation import validate_fmu
import numpy as np

from harness import engine

import pytest

pytestmark = pytest.mark.engine

SCENE = os.path.join(os.path.dirname(__file__), "..", "fmu", "scenes", "friction-damper.toml")
SAME_ENGINE = 1e-9


def _cli_friction(cli, workdir, text, name):
    result = engine.solve(cli, text, workdir, name, ("--no-estimate",))
    with open(result.path) as fh:
        raw = json.load(fh)
    return raw, raw["friction"][0]


def _close(got, want, what):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    scale = max(np.ptp(want), np.max(np.abs(want)), np.finfo(float).tiny)
    worst = float(np.max(np.abs(got - want)))
    assert worst <= SAME_ENGINE * scale, f"{what}: the FMU differs from the CLI by {worst:.3e} (range {scale:.3e})"


def _simulate(fmu, raw, start_values=None):
    k, period = raw["steps"], raw["period"]
    sim = fmpy.simulate_fmu(fmu, start_time=0.0, stop_time=period, output_interval=period / k, start_values=start_values or {})
    assert len(sim) == k + 1
    return {name: np.asarray(sim[name][:k]) for name in sim.dtype.names}


def test_fmpy_friction_loop_equals_the_cli(cli, workdir):
    with open(SCENE) as fh:
        text = fh.read()
    raw, want = _cli_friction(cli, workdir, text, "friction_loop")
    fmu = engine.build_fmu(cli, text, workdir, "friction_loop")
    assert not validate_fmu(fmu), "fmpy validate"
    md = fmpy.read_model_description(fmu)
    units = {v.name: v.declaredType.unit if v.declaredType else v.unit for v in md.modelVariables}
    assert units["friction[0].force"] == "N" and units["friction[0].slip_velocity"] == "m/s", units
    kinds = {v.name: (v.type, v.causality, v.variability) for v in md.modelVariables}
    assert kinds["friction[0].stuck"] == ("Boolean", "output", "discrete")
    assert kinds["normal_force_scale"] == ("Real", "parameter", "tunable")
    got = _simulate(fmu, raw)
    # The loop: force against the tangential displacement (DOF 0, direction +1).
    _close(got["displacement[0]"], want["displacement"], "loop abscissa displacement[0]")
    _close(got["friction[0].force"], want["force"], "loop ordinate friction[0].force")
    _close(got["friction[0].slip_velocity"], want["slip_velocity"], "friction[0].slip_velocity")
    assert list(got["friction[0].stuck"].astype(bool)) == want["stuck"], "friction[0].stuck"
    assert any(want["stuck"]) and not all(want["stuck"]), "the damper sticks and slips"
    # Same loop, same area: the energy per cycle ∮ f du by the trapezoidal rule on the FMU's samples.
    u, f = got["displacement[0]"], got["friction[0].force"]
    area = 0.5 * np.sum((np.roll(f, -1) + f) * (np.roll(u, -1) - u))
    ref = 0.5 * np.sum((np.roll(want["force"], -1) + want["force"]) * (np.roll(want["displacement"], -1) - want["displacement"]))
    assert abs(area - ref) <= SAME_ENGINE * abs(ref) and area > 0.0, (area, ref)


def test_fmpy_normal_force_scale_equals_the_scene_with_the_load_scaled(cli, workdir):
    with open(SCENE) as fh:
        text = fh.read()
    halved = text.replace("normal_force = 2.0", "normal_force = 1.0", 1)
    assert halved != text
    raw, want = _cli_friction(cli, workdir, halved, "friction_halved")
    fmu = engine.build_fmu(cli, text, workdir, "friction_scaled")
    got = _simulate(fmu, raw, {"normal_force_scale": 0.5})
    _close(got["friction[0].force"], want["force"], "friction[0].force at normal_force_scale 0.5")
    _close(got["displacement[0]"], raw["displacement"]["0"], "displacement[0] at normal_force_scale 0.5")
    assert list(got["friction[0].stuck"].astype(bool)) == want["stuck"]
