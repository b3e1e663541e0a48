"""Every shipped scene (fmu/scenes/, reduced blades included) packaged as an FMU and run the way a
user runs it, with fmpy.simulate_fmu, gives the CLI's displacements at the k instants to 1e-9 of
each output's peak-to-peak amplitude. The Rust side of the same matrix (CLI, C API, FMU under a
Rust host) is tests/frontends.rs; `fmpy validate` passing is not enough (the blades once passed it
and failed in simulate_fmu).
"""
import json
import os

import fmpy
from fmpy.validation import validate_fmu
import numpy as np
import pytest

from harness import engine

pytestmark = pytest.mark.engine

SCENES = os.path.join(os.path.dirname(__file__), "..", "fmu", "scenes")
SAME_ENGINE = 1e-9


def _scenes():
    return sorted(f for f in os.listdir(SCENES) if f.endswith(".toml"))


@pytest.mark.parametrize("scene", _scenes())
def test_fmpy_simulate_matches_the_cli(cli, workdir, scene):
    name = "frontend_" + scene[:-5].replace("-", "_")
    with open(os.path.join(SCENES, scene)) as fh:
        text = fh.read()
    result = engine.solve(cli, text, workdir, name)
    with open(result.path) as fh:
        raw = json.load(fh)
    k, period = raw["steps"], raw["period"]
    fmu = engine.build_fmu(cli, text, workdir, name)
    problems = validate_fmu(fmu)
    assert not problems, f"fmpy validate {scene}: {problems}"
    sim = fmpy.simulate_fmu(fmu, start_time=0.0, stop_time=period, output_interval=period / k)
    assert len(sim) == k + 1, f"{scene}: {len(sim)} rows for {k} steps"
    for key, x in raw["displacement"].items():
        x = np.asarray(x)
        got = np.asarray(sim[f"displacement[{key}]"][:k])
        scale = max(np.ptp(x), np.finfo(float).tiny)
        worst = float(np.max(np.abs(got - x)))
        assert worst <= SAME_ENGINE * scale, f"{scene}: displacement[{key}] differs from the CLI by {worst:.3e} (peak-to-peak {scale:.3e})"
