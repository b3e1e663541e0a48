"""Coupled normal–tangential friction (issue 25): the exact event-driven reference
(validation/peers/coupled_exact.py) checked against Den Hartog's closed form where the coupling
vanishes, and the CLI's LCP on examples/friction/coupled.toml converging to its exact orbit at
first order. About a second.
"""
from __future__ import annotations

import numpy as np
import pytest

from peers import coupled_exact as ce
from test_friction_peer import den_hartog


@pytest.mark.parametrize("omega,slip", [(0.6, 0.3), (1.7, 0.2)])
def test_uncoupled_reference_meets_den_hartog(omega, slip):
    # k_xy = 0 and a constant normal load N0: the plane's static force is λ = k_c N0/(k_y + k_c),
    # so μλ = slip with N0 = (1 + k_c)/k_c and μ = slip; x'' + x = cos Ωt − μλ sgn ẋ (c_x = 0).
    kc = 10.0
    s = ce.CoupledSystem(K=np.eye(2), C=np.diag([0.0, 0.8]), plane=kc, mu=slip, F0=np.array([0.0, -(1 + kc) / kc]),
                         Fc=np.array([1.0, 0.0]), Fs=np.zeros(2), omega=omega)
    orbit = ce.solve(s)
    # Continuous motion: the reversals (slip ends at ẋ = 0) are the extremes of x.
    ends = [y[0] for _, phase, y in orbit.segments[1:] if phase in (ce.SLIP_UP, ce.SLIP_DOWN)]
    amplitude = 0.5 * (max(ends) - min(ends))
    exact = den_hartog(slip, omega)
    err = abs(amplitude - exact) / exact
    print(f"Ω {omega}, μλ {slip}: amplitude {amplitude:.15f}, Den Hartog {exact:.15f}, error {err:.1e}")
    assert err < 1e-10
    assert [name for _, name in orbit.events()].count("stick") == 0
    assert all(p != ce.FREE for _, p, _ in orbit.segments)


@pytest.mark.engine
def test_cli_converges_to_the_exact_coupled_orbit(cli):
    orbit = ce.solve(ce.example())
    rows = ce.cli_errors(orbit, steps=(128, 256), binary=cli)
    (_, (e1, _), _, _), (_, (e2, _), _, _) = rows
    print("errors (x, y, λ_n) at k = 128:", e1, "k = 256:", e2)
    for a, b in zip(e1, e2):
        assert b < a and 0.8 < np.log2(a / b) < 1.3
    assert e2[0] < 0.1 and e2[1] < 0.04


@pytest.mark.engine
def test_fmu_equals_the_cli_on_the_coupled_scene(cli, tmp_path):
    # The FMU's contact[0].force and friction[0].force/stuck at t = iT/16 (instants of k = 256)
    # against the CLI's JSON of the same scene.
    import json
    import subprocess

    import fmpy
    fmu, out = str(tmp_path / "coupled.fmu"), str(tmp_path / "r.json")
    subprocess.run([cli, "fmu", ce.SCENE, "-o", fmu], check=True, capture_output=True)
    subprocess.run([cli, "solve", ce.SCENE, "--no-estimate", "-o", out], check=True, capture_output=True)
    raw = json.load(open(out))
    T = 2 * np.pi / 1.5
    names = ["contact[0].force", "friction[0].force", "friction[0].stuck"]
    r = fmpy.simulate_fmu(fmu, stop_time=T * 15 / 16, output_interval=T / 16, output=names)
    want = [np.array(raw["contacts"][0]["force"])[::16], np.array(raw["friction"][0]["force"])[::16],
            np.array(raw["friction"][0]["stuck"])[::16]]
    assert len(r) == 16
    for name, w in zip(names, want):
        worst = np.abs(np.asarray(r[name], dtype=float) - w.astype(float)).max()
        print(f"{name}: FMU against CLI {worst:.1e}")
        assert worst <= 1e-9 * max(np.abs(w.astype(float)).max(), 1.0)
