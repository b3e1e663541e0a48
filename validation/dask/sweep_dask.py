"""A frequency sweep of periodic-contact distributed over a Dask cluster (dask.distributed).

When one machine is not enough (a fine model, thousands of points, several scenes), each sweep
point becomes one Dask task that runs the command-line tool on its own:

    periodic-contact solve SCENE.toml --frequency ω -o point.json

and reduces the JSON result to the quantities of the CLI's own sweep CSV (`periodic-contact
sweep`): the amplitude (peak-to-peak / 2) of every displacement output, the largest force and the
contact fraction of every contact, the LCP size and the pivots. The points are the CLI sweep's:
ω_i = from + (to − from)·i/(points − 1).

Tasks are independent, so every point is solved cold (no warm start from a neighbour): compare
with `periodic-contact sweep --cold`. (The CLI's warm-started sweep follows one branch of the
response through a hysteresis region; cold solves may land on the other branch there.)

Usage
-----
    # a LocalCluster on this machine (2 worker processes, 1 thread each):
    validation/.venv/bin/python validation/dask/sweep_dask.py fmu/scenes/blade-casing-coarse.toml \\
        --from 2000 --to 2700 --points 40 --workers 2 -o sweep_dask.csv

    # an existing cluster (`dask scheduler` + `dask worker tcp://HOST:8786` on each node): the
    # CLI (--cli or PC_CLI) and the scene, with its Matrix Market files, must be at the same
    # paths on every worker (a shared file system), and --workdir must be shared too.
    python validation/dask/sweep_dask.py SCENE.toml --from A --to B --points N --scheduler tcp://HOST:8786

From Python: `run_sweep(client, cli, scene, frequencies, workdir)` returns one dict per point.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_CLI = os.path.abspath(os.path.join(HERE, "..", "..", "target", "release", "periodic-contact"))


def frequencies(start: float, stop: float, n: int) -> list[float]:
    """The CLI sweep's points: start + (stop − start)·i/(n − 1), evaluated in the same order."""
    if n < 1:
        raise ValueError(f"points: is {n}, a sweep needs at least one point")
    if n == 1:
        return [start]
    return [start + (stop - start) * i / (n - 1) for i in range(n)]


def peak_to_peak(x: list[float]) -> float:
    return max(x) - min(x) if x else 0.0


def solve_point(cli: str, scene: str, omega: float, workdir: str) -> dict:
    """One task: solve the scene at ω with the CLI and summarise the JSON result."""
    out = os.path.join(workdir, f"point-{omega!r}.json")
    t0 = time.perf_counter()
    cp = subprocess.run([cli, "solve", scene, "--frequency", repr(omega), "-o", out],
                        capture_output=True, text=True, timeout=600)
    wall = time.perf_counter() - t0
    if cp.returncode != 0:
        return {"frequency": omega, "status": f"exit {cp.returncode}: {cp.stderr.strip()[-500:]}", "time_s": wall}
    with open(out) as f:
        r = json.load(f)
    os.remove(out)
    row = {"frequency": omega}
    for dof, series in r["displacement"].items():
        row[f"amplitude_{dof}"] = peak_to_peak(series) / 2.0
    for i, c in enumerate(r["contacts"]):
        row[f"max_force_c{i}_dof{c['dof']}"] = max(c["force"]) if c["force"] else 0.0
        row[f"contact_fraction_c{i}_dof{c['dof']}"] = sum(1 for v in c["force"] if v > 0.0) / max(1, len(c["force"]))
    row["lcp_size"] = r["lcp"]["size"]
    row["pivots"] = r["lcp"]["pivots"]
    row["time_s"] = wall
    row["status"] = r["lcp"]["status"]
    return row


def run_sweep(client, cli: str, scene: str, freqs: list[float], workdir: str) -> list[dict]:
    """Maps `solve_point` over the frequencies on the cluster of `client`; rows in input order."""
    import cloudpickle

    # Ship this module's functions by value: the workers need not import it.
    module = sys.modules[__name__]
    if __name__ != "__main__":
        cloudpickle.register_pickle_by_value(module)
    cli, scene, workdir = os.path.abspath(cli), os.path.abspath(scene), os.path.abspath(workdir)
    futures = client.map(solve_point, [cli] * len(freqs), [scene] * len(freqs), freqs, [workdir] * len(freqs),
                         pure=False)
    return client.gather(futures)


def write_csv(rows: list[dict], path: str) -> None:
    keys: list[str] = []
    for r in rows:
        keys.extend(k for k in r if k not in keys)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def cluster_arguments(ap: argparse.ArgumentParser, files: str, output: str) -> None:
    """The options every Dask example shares: the cluster, the CLI, the work folder, the output."""
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (without --scheduler)")
    ap.add_argument("--scheduler", help="address of an existing scheduler, e.g. tcp://host:8786")
    ap.add_argument("--cli", default=os.environ.get("PC_CLI", DEFAULT_CLI))
    ap.add_argument("--workdir", help=f"folder for the {files} (default: a temporary one)")
    ap.add_argument("-o", "--output", default=output)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--from", dest="start", type=float, required=True, help="first ω [rad/s]")
    ap.add_argument("--to", dest="stop", type=float, required=True, help="last ω [rad/s]")
    ap.add_argument("--points", type=int, default=20)
    cluster_arguments(ap, "per-point JSON files", "sweep_dask.csv")
    a = ap.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    freqs = frequencies(a.start, a.stop, a.points)
    workdir = a.workdir or tempfile.mkdtemp(prefix="pc-dask-")
    os.makedirs(workdir, exist_ok=True)
    t0 = time.perf_counter()
    if a.scheduler:
        client = Client(a.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        rows = run_sweep(client, a.cli, a.scene, freqs, workdir)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    write_csv(rows, a.output)
    failed = [r for r in rows if r["status"] != "solved"]
    print(f"{len(rows)} points on {a.scheduler or f'a LocalCluster of {a.workers} workers'} in "
          f"{time.perf_counter() - t0:.2f} s: {len(rows) - len(failed)} solved, {len(failed)} failed -> {a.output}",
          file=sys.stderr)
    for r in failed:
        print(f"  ω = {r['frequency']}: {r['status']}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
