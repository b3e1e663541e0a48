"""The Dask example (validation/dask/sweep_dask.py) on a LocalCluster of 2 workers equals the
CLI's own sweep (`periodic-contact sweep --cold`) at the same points."""
import csv
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.engine

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "fmu", "scenes", "blade-casing-coarse.toml")
sys.path.insert(0, os.path.join(HERE, "dask"))

import sweep_dask  # noqa: E402


def read_csv(path):
    """Rows keyed by column key: the CLI's header names a unit after the key ("amplitude_1903 [m]")."""
    with open(path) as f:
        return [{k.split(" [")[0]: v for k, v in row.items()} for row in csv.DictReader(f)]


def test_dask_sweep_on_a_local_cluster_equals_the_cli_sweep(cli, workdir):
    distributed = pytest.importorskip("distributed")
    start, stop, n = 2200.0, 2400.0, 9
    freqs = sweep_dask.frequencies(start, stop, n)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            assert len(client.scheduler_info()["workers"]) == 2
            rows = sweep_dask.run_sweep(client, cli, SCENE, freqs, workdir)
    assert [r["frequency"] for r in rows] == freqs
    assert all(r["status"] == "solved" for r in rows), rows

    out = os.path.join(workdir, "cli_sweep.csv")
    cp = subprocess.run([cli, "sweep", SCENE, "--from", repr(start), "--to", repr(stop), "--points", str(n),
                         "--cold", "--no-plot", "--quiet", "-o", out], capture_output=True, text=True, timeout=300)
    assert cp.returncode == 0, cp.stderr
    ref = read_csv(out)
    assert len(ref) == n
    compared = 0
    for r, s in zip(rows, ref):
        assert float(s["frequency"]) == r["frequency"]
        for key, value in r.items():
            if key.startswith(("amplitude_", "max_force_", "contact_fraction_")):
                expected = float(s[key])
                assert value == pytest.approx(expected, rel=1e-9, abs=1e-12 * max(1.0, abs(expected))), (r["frequency"], key)
                compared += 1
        assert r["lcp_size"] == int(s["lcp_size"])
        assert r["pivots"] == int(s["pivots"])
    # 3 displacement outputs and 3 contacts × 2 quantities per point.
    assert compared == 9 * n
    # The sweep crosses the rubbing range: some points are in contact.
    assert any(float(s["max_force_c0_dof1868"]) > 0.0 for s in ref)


def test_the_example_runs_as_a_script(cli, workdir):
    pytest.importorskip("distributed")
    out = os.path.join(workdir, "dask_script.csv")
    cp = subprocess.run([sys.executable, os.path.join(HERE, "dask", "sweep_dask.py"), SCENE, "--from", "2250",
                         "--to", "2300", "--points", "3", "--workers", "2", "--cli", cli, "-o", out],
                        capture_output=True, text=True, timeout=300)
    assert cp.returncode == 0, cp.stderr
    rows = read_csv(out)
    assert [float(r["frequency"]) for r in rows] == [2250.0, 2275.0, 2300.0]
    assert all(r["status"] == "solved" for r in rows)


def test_dask_continuation_over_force_levels(cli, workdir):
    """validation/dask/continue_dask.py: one frequency branch per force level on a LocalCluster.
    Level 0.05 of NLvib 03 never reaches the clearance, so its branch is the linear response,
    known in closed form; level 1 is NLvib 03 itself, whose events the exact-flow reference lists."""
    distributed = pytest.importorskip("distributed")
    import json

    import numpy as np
    import continue_dask

    scene = os.path.join(HERE, "nlvib03", "nlvib03.toml")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            results = continue_dask.run_levels(client, cli, scene, [0.05, 1.0], 0.5, 0.8, workdir)
    low, full = results
    assert low["stop"] == "reached" and full["stop"] == "reached"
    # Closed form: X = (K − Ω² M + iΩD)⁻¹ f, amplitude of DOF 0 = |X_0|; cds at k = 4096 is O((ωh)²) ≈ 1e-5 off.
    K = np.array([[1.0, -1.0], [-1.0, 2.0]])
    D = 0.03 * K
    worst = 0.0
    for row in low["rows"]:
        omega = float(row["frequency [rad/s]"])
        x = np.linalg.solve(K - omega**2 * np.eye(2) + 1j * omega * D, np.array([0.0, 0.1 * 0.05]))
        worst = max(worst, abs(float(row["amplitude_0 [m]"]) - abs(x[0])) / abs(x[0]))
    assert worst < 1e-4, worst
    assert low["events"] == [] and max(float(r["amplitude_0 [m]"]) for r in low["rows"]) < 1.0
    with open(os.path.join(HERE, "nlvib03", "reference.json")) as f:
        ref = [(e["type"], e["omega"]) for e in json.load(f)["events"] if e.get("branch") == "T"]
    ours = [(e["type"], e["frequency"]) for e in full["events"]]
    assert len(ours) == len(ref), ours
    for kind, omega in ref:
        assert min(abs(o - omega) for k, o in ours if k == kind) < 3e-4, (kind, omega, ours)
