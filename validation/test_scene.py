"""The scene writer emits the TOML contract; parsed back (tomllib, independent of the engine's
parser) it gives the same system. No binaries needed."""
import tomllib

import numpy as np
import pytest

from harness.cases import CASES
from harness.scene import scene_toml, system_from_toml


@pytest.mark.parametrize("name", list(CASES))
def test_scene_roundtrip(name):
    case = CASES[name]
    run = case.runs[0]
    text = scene_toml(case.system, run.scheme, run.steps, run.pairing, comment=case.title)
    d = tomllib.loads(text)
    assert set(d) <= {"structure", "damping", "excitation", "force", "contact", "discretization", "output"}
    assert d["discretization"] == {"scheme": run.scheme, "steps": run.steps, "pairing": run.pairing}
    assert d["output"] == {"displacement": case.output_dofs, "velocity": case.output_dofs}
    s2, _ = system_from_toml(text)
    s = case.system
    for a, b in ((s.mass, s2.mass), (s.stiffness, s2.stiffness), (s.damping, s2.damping)):
        np.testing.assert_array_equal(a, b)
    assert s2.omega == s.omega and s2.forces == s.forces and s2.contacts == s.contacts
    for c, contact in zip(d.get("contact", []), s.contacts):
        assert c["direction"] in (1, -1)
        assert ("stiffness" in c) == (not contact.rigid)


def test_scene_matches_contract_example():
    """The contract's example scene, written from Python, has exactly the example's keys."""
    from marching.model import Contact, Force, Motion, System

    s = System.build([[1.0]], [[1.0]], 1.3, forces=[Force(0, 1.0, 1, 0.0)],
                     contacts=[Contact(0, 1.0, 1, 10.0, (Motion(0.1, 2, 0.0),))], damping=[[0.05]])
    d = tomllib.loads(scene_toml(s, "cds", 256, "forward"))
    assert d == {
        "structure": {"mass": [[1.0]], "stiffness": [[1.0]]},
        "damping": {"matrix": [[0.05]]},
        "excitation": {"frequency": 1.3},
        "force": [{"dof": 0, "amplitude": 1.0, "harmonic": 1, "phase": 0.0}],
        "contact": [{"dof": 0, "direction": 1, "gap": 1.0, "stiffness": 10.0,
                     "motion": [{"amplitude": 0.1, "harmonic": 2, "phase": 0.0}]}],
        "discretization": {"scheme": "cds", "steps": 256, "pairing": "forward"},
        "output": {"displacement": [0], "velocity": [0]},
    }
