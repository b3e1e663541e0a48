"""Every shipped scene (fmu/scenes/, reduced blades included) packaged as an FMU and run the way a
user runs it, with fmpy.simulate_fmu, gives the CLI's displacements at the k instants to 1e-9 of
each output's peak-to-peak amplitude. The Rust side of the same matrix (CLI, C API, FMU under a
Rust host) is tests/frontends.rs; `fmpy validate` passing is not enough (the blades once passed it
and failed in simulate_fmu).
"""
import json
import os
import shutil

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
    # The files the scenes reference (Matrix Market, CalculiX) sit in fmu/scenes/data/.
    shutil.copytree(os.path.join(SCENES, "data"), os.path.join(workdir, "data"), dirs_exist_ok=True)
    # The orbit is compared, not the error estimate (tested in test_cli.py and tests/): its
    # second solve at 2k costs the fine blade 80 s of dense Lemke.
    result = engine.solve(cli, text, workdir, name, ("--no-estimate",))
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


def test_fmpy_reads_the_units_of_a_scene_in_mm(cli, workdir):
    """The compliant stop with `[units] length = "mm"`, `force = "kN"`: `fmpy validate` passes and fmpy
    reads the unit of every Real (dimensionless scale factors "1", the LCP residual none) and the
    SI factor of each unit."""
    with open(os.path.join(SCENES, "compliant-stop.toml")) as fh:
        text = fh.read() + '\n[units]\nlength = "mm"\nforce = "kN"\n'
    fmu = engine.build_fmu(cli, text, workdir, "frontend_units_mm")
    problems = validate_fmu(fmu)
    assert not problems, problems
    md = fmpy.read_model_description(fmu)
    unit = {v.name: v.unit for v in md.modelVariables if v.type == "Real"}
    expected = {"frequency": "rad/s", "frequency_in": "rad/s", "force_scale": "1", "gap_offset": "mm",
                "displacement[0]": "mm", "contact[0].force": "kN", "contact[0].gap": "mm", "lcp.residual": None}
    for name, u in expected.items():
        assert unit[name] == u, (name, unit[name])
    assert all(u is not None for name, u in unit.items() if name != "lcp.residual"), unit
    defs = {u.name: u.baseUnit for u in md.unitDefinitions}
    assert set(defs) == {u for u in unit.values() if u is not None}
    assert (defs["mm"].m, defs["mm"].factor) == (1, 0.001)
    assert (defs["kN"].kg, defs["kN"].m, defs["kN"].s, defs["kN"].factor) == (1, 1, -2, 1000.0)
    assert (defs["rad/s"].rad, defs["rad/s"].s) == (1, -1)
    gap = next(v for v in md.modelVariables if v.name == "contact[0].gap")
    assert "negative = penetration" in gap.description, gap.description
