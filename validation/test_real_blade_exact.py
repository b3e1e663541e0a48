"""The CalculiX-assembled blade with compliant tip contacts against the grid-free exact orbit
(issue 23; README "Real-blade benchmark", "Compliant tips against the exact flow").

The reference is validation/exact_flow.py on the model the CLI exports (`periodic-contact
export`): piecewise-linear flows between contact switches, Newton shooting, no time grid.

- test_coarse_calculix_blade_compliant_cds_within_1e4 (default run, ccx needed, skipped with the
  reason without it): the generator's coarse blade as a CalculiX deck (24 × 8 × 2 C3D8I, the deck
  of test_calculix_blade_fmu.py), massless boundary, 9 radial compliant tip contacts of 1e7 N/m,
  the real blade's two-lobe casing: cds within 1e-4 of the exact orbit at K_COARSE, order 2 ± 0.3
  over the last doubling.
- test_real_blade_compliant_within_1e4 (opt-in: PC_REAL_BLADE_EXACT=1, a few minutes):
  examples/real-blade/blade-compliant.toml (66 480 DOFs, 17 contacts) reduced to 69 DOFs both
  ways. Massless boundary at ω = 2300 rad/s (near the first bending mode) and 2100 rad/s (chosen
  before any run): cds and fourier within 1e-4 at the k measured by validation/exact_flow_blade.py,
  cds at order 2 ± 0.3 over the last doubling. Craig–Bampton at 2300 rad/s: galerkin and cds
  within 1e-4 at k = 16384.
- test_real_blade_compliant_exact_sweep_against_exact_flow (opt-in: PC_REAL_BLADE_SWEEP=1, ~1 min):
  the must-show 200-point exact sweep of blade-compliant.toml (2000–2600 rad/s); at 3 of its points
  drawn with random.Random(2311) (fixed before any run) the exact orbit of the exported model at the
  sweep's ω: each output's amplitude (half the peak-to-peak) within 1e-4 relative.
"""
import csv
import random
import json
import os
import re
import subprocess
import tomllib

import numpy as np
import pytest

from exact_flow import ContactModel, ExactFlow, compare_with_grid
from test_calculix_blade_fmu import REAL, _ccx_or_skip, _deck_and_ccx, _tip_contacts

pytestmark = pytest.mark.engine

TARGET = 1e-4
# cds on the coarse CalculiX blade: the error falls below 1e-4 at this k (measured, README)
K_COARSE = 4096
# (reduction, ω [rad/s]) → (scheme, k where the error is ≤ 1e-4, k/2 for the order or None): README's
# table. Massless boundary: cds 5.4e-5 and 5.8e-5 at k = 8192 (order 2.00, 1.99), fourier 8.9e-5 at
# 512 and 1.8e-5 at 1024 (its k = 512 is 1.3e-4 at 2100 rad/s). Craig–Bampton at 2300 rad/s:
# galerkin 6.2e-5 and cds 7.7e-5 at k = 16384 (their stability limits are 8192 and 16384). At
# 2100 rad/s both are 1.4e-4 at 16384 and 5.2e-5 / 5.7e-5 at 32768 (validation/exact_flow_blade.py),
# not asserted here: that exact orbit's Newton stops at 2.85e-12–4e-12, above the 1e-12 checked below.
REAL_CASES = {
    ("massless-boundary", 2300.0): (("cds", 8192, 4096), ("fourier", 512, None)),
    ("massless-boundary", 2100.0): (("cds", 8192, 4096), ("fourier", 1024, None)),
    ("craig-bampton", 2300.0): (("galerkin", 16384, None), ("cds", 16384, None)),
}


def _real_blade_text(name, job):
    """examples/real-blade/NAME with its CalculiX job's path made absolute."""
    with open(os.path.join(REAL, name)) as fh:
        text = fh.read()
    text, n = re.subn(r'(?m)^calculix = "job/blade"', f'calculix = "{os.path.join(job, "blade")}"', text)
    assert n == 1, f"examples/real-blade/{name} changed: update this test"
    return text


def _solve(cli, scene_text, folder, name):
    scene = os.path.join(folder, f"{name}.toml")
    with open(scene, "w") as fh:
        fh.write(scene_text)
    out = os.path.join(folder, f"{name}.json")
    p = subprocess.run([cli, "solve", scene, "--no-estimate", "-o", out], capture_output=True, text=True)
    assert p.returncode == 0, f"{name}: exit {p.returncode}: {p.stderr[-1500:]}"
    with open(out) as fh:
        return json.load(fh)


def _with(text, scheme, k):
    text = re.sub(r'(?m)^scheme = "\w+"', f'scheme = "{scheme}"', text)
    text = re.sub(r"(?m)^steps = \d+", f"steps = {k}", text)
    return re.sub(r'(?m)^pairing = "\w+"\n', "", text)


def _real_blade_job(cli):
    """examples/real-blade/job (CalculiX's matrices of the 66 480-DOF blade), built when absent."""
    job = os.path.join(REAL, "job")
    if not all(os.path.exists(os.path.join(job, f"blade.{e}")) for e in ("sti", "mas", "dof")):
        _deck_and_ccx(cli, os.path.join(REAL, "mesh.toml"), job)
    return job


def _errors_against_exact(cli, text, folder, runs):
    """Export the scene's model, solve `runs` [(scheme, k)], build the exact orbit from the first
    answer's contact forces; the error of each run (max |x − x_exact| / each output's peak-to-peak)."""
    scene = os.path.join(folder, "export.toml")
    with open(scene, "w") as fh:
        fh.write(_with(text, *runs[0]))  # a scheme and k the model accepts (cds on Craig–Bampton needs k ≥ 10 201)
    model = os.path.join(folder, "model")
    p = subprocess.run([cli, "export", scene, "-o", model], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-1500:]
    answers = {(s, k): _solve(cli, _with(text, s, k), folder, f"{s}-{k}") for s, k in runs}
    flow = ExactFlow(ContactModel.load(model))
    first = answers[runs[0]]
    orbit = flow.periodic_orbit(flow.guess_from_forces(first["time"], np.array([c["force"] for c in first["contacts"]])))
    assert orbit.history[-1] < 1e-12 and len(orbit.switches()) >= 2 * flow.mdl.m, (orbit.history, len(orbit.switches()))
    errs = {run: compare_with_grid(orbit, r)["max_over_orbit"] for run, r in answers.items()}
    print(f"\n{os.path.basename(folder)}: n = {flow.mdl.n}, m = {flow.mdl.m}, {len(orbit.switches())} switches, "
          + ", ".join(f"{s} k = {k}: {e:.2e}" for (s, k), e in errs.items()))
    return errs


def test_coarse_calculix_blade_compliant_cds_within_1e4(cli, workdir):
    _ccx_or_skip()
    folder = os.path.join(workdir, "calculix_coarse_blade_compliant")
    job = os.path.join(folder, "job")
    os.makedirs(folder, exist_ok=True)
    mesh = os.path.join(folder, "mesh.toml")
    with open(mesh, "w") as fh:
        fh.write('[structure]\ngenerator = { kind = "blade", preset = "coarse", element = "hex8-incompatible" }\n[excitation]\nfrequency = 2300.0\n')
    _deck_and_ccx(cli, mesh, job)
    with open(os.path.join(job, "blade.inp")) as fh:
        tip, contacts = _tip_contacts(fh.read())
    contacts = contacts.replace("gap = 1.2e-5\n", "gap = 1.2e-5\nstiffness = 1e7\n")
    with open(os.path.join(REAL, "blade-compliant.toml"), "rb") as fh:
        casing = tomllib.load(fh)["casing"]
    harmonics = ",\n".join(f"  {{ order = {t['order']}, amplitude = {t['amplitude']!r} }}" for t in casing["harmonics"])
    text = (
        f'[structure]\ncalculix = "{os.path.join(job, "blade")}"\n[reduction]\nmethod = "massless-boundary"\nmodes = 10\n'
        "[damping]\nmodal_ratios = [0.005]\n[excitation]\nfrequency = 2300.0\n"
        f"[casing]\nlobes = 2\nradius = {casing['radius']!r}\naxis = {casing['axis']!r}\ncenter = {casing['center']!r}\nharmonics = [\n{harmonics}\n]\n"
        f'{contacts}[discretization]\nscheme = "cds"\nsteps = 256\n'
        f'[output]\ndisplacement = ["{tip[0]}:z", "{tip[len(tip) // 2]}:y", "{tip[-1]}:z"]\n'
    )
    errs = _errors_against_exact(cli, text, folder, [("cds", K_COARSE // 2), ("cds", K_COARSE)])
    e_half, e = errs[("cds", K_COARSE // 2)], errs[("cds", K_COARSE)]
    assert e <= TARGET, errs
    assert abs(np.log2(e_half / e) - 2) < 0.3, errs


@pytest.mark.skipif(os.environ.get("PC_REAL_BLADE_EXACT", "") in ("", "0"),
                    reason="opt-in: PC_REAL_BLADE_EXACT=1 (the 66 480-DOF real blade with compliant tips, a few minutes)")
@pytest.mark.parametrize("method,omega", sorted(REAL_CASES))
def test_real_blade_compliant_within_1e4(cli, workdir, method, omega):
    _ccx_or_skip()
    job = _real_blade_job(cli)
    text = _real_blade_text("blade-compliant.toml", job)
    text, n2 = re.subn(r"(?m)^frequency = [0-9.eE+-]+", f"frequency = {omega!r}", text, count=1)
    text, n3 = re.subn(r'(?m)^method = "massless-boundary"', f'method = "{method}"', text)
    assert (n2, n3) == (1, 1), "examples/real-blade/blade-compliant.toml changed: update this test"
    folder = os.path.join(workdir, f"real_blade_compliant_{method}_{omega:.0f}")
    os.makedirs(folder, exist_ok=True)
    runs = []
    for scheme, k, k_half in REAL_CASES[(method, omega)]:
        runs += [(scheme, k)] + ([(scheme, k_half)] if k_half else [])
    errs = _errors_against_exact(cli, text, folder, runs)
    for scheme, k, k_half in REAL_CASES[(method, omega)]:
        assert errs[(scheme, k)] <= TARGET, (scheme, k, errs)
        if k_half:
            assert abs(np.log2(errs[(scheme, k_half)] / errs[(scheme, k)]) - 2) < 0.3, (scheme, errs)


SWEEP_POINTS = 200


@pytest.mark.skipif(os.environ.get("PC_REAL_BLADE_SWEEP", "") in ("", "0"),
                    reason="opt-in: PC_REAL_BLADE_SWEEP=1 (the 200-point exact sweep of the real blade, ~1 min)")
def test_real_blade_compliant_exact_sweep_against_exact_flow(cli, workdir):
    _ccx_or_skip()
    text = _real_blade_text("blade-compliant.toml", _real_blade_job(cli))
    folder = os.path.join(workdir, "real_blade_compliant_sweep")
    os.makedirs(folder, exist_ok=True)
    scene, table = os.path.join(folder, "sweep.toml"), os.path.join(folder, "sweep.csv")
    with open(scene, "w") as fh:
        fh.write(text)
    p = subprocess.run([cli, "sweep", scene, "--from", "2000", "--to", "2600", "--points", str(SWEEP_POINTS), "--exact",
                        "--no-plot", "--threads", "1", "--quiet", "-o", table], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-1500:]
    with open(table) as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == SWEEP_POINTS and all(r["status"] == "solved" for r in rows), {r["status"] for r in rows}
    worst = 0.0
    for i in random.Random(2311).sample(range(SWEEP_POINTS), 3):  # drawn before any run (session 23: 39, 103, 74)
        row, omega = rows[i], rows[i]["frequency [rad/s]"]
        assert float(row["error_estimate_relative"]) <= 1e-3, row
        at = os.path.join(folder, f"point{i}")
        os.makedirs(at, exist_ok=True)
        with open(os.path.join(at, "scene.toml"), "w") as fh:
            fh.write(re.sub(r"(?m)^frequency = [0-9.eE+-]+", f"frequency = {omega}", text, count=1))
        p = subprocess.run([cli, "export", os.path.join(at, "scene.toml"), "-o", os.path.join(at, "model")],
                           capture_output=True, text=True)
        assert p.returncode == 0, p.stderr[-1500:]
        flow = ExactFlow(ContactModel.load(os.path.join(at, "model")))
        orbit = flow.periodic_orbit(flow.guess_by_marching())
        assert orbit.history[-1] < 1e-10, orbit.history  # Newton's residual stalls at ~1e-12 (round-off)
        for key in flow.mdl.outputs:
            exact = orbit.peak_to_peak(key) / 2
            err = abs(float(row[f"amplitude_{key} [m]"]) - exact) / exact
            print(f"\nω = {omega} rad/s ({row['source']}), output {key}: amplitude {exact:.10e} m, sweep within {err:.2e}")
            worst = max(worst, err)
    assert worst <= TARGET, worst
