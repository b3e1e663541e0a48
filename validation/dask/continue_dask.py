"""Continuation in several parameters at once over a Dask cluster: one frequency branch per force
level (issue 13, item 5).

Each force level is one Dask task that writes the scene with every `[[force]] amplitude` scaled by
the level and runs the command-line continuation on it:

    periodic-contact continue SCENE_level.toml --param frequency --from A --to B -o branch.csv

The branches are gathered into one CSV with a `force_scale` column in front of the CLI's own
columns (frequency, amplitude_<dof>, stable, multiplier, period_multiple, event, certified), one
events JSON keyed by level, and a PNG of the response curves (unstable parts dashed, events
marked), one colour per level.

Usage
-----
    validation/.venv/bin/python validation/dask/continue_dask.py validation/nlvib03/nlvib03.toml \\
        --from 0.5 --to 0.8 --levels 0.2,0.5,1 --workers 2 -o levels.csv

    # an existing cluster: --scheduler tcp://HOST:8786 (the CLI, the scene and --workdir on a
    # shared file system, as for sweep_dask.py)

From Python: `run_levels(client, cli, scene, levels, start, stop, workdir)` returns one dict per
level: {"force_scale", "rows", "events", "stop", "seconds"}.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from sweep_dask import DEFAULT_CLI, cluster_arguments  # noqa: E402

_AMPLITUDE = re.compile(r"^(\s*amplitude\s*=\s*)([-+0-9.eE]+)(.*)$")


def scaled_scene(text: str, level: float) -> str:
    """The scene with every force amplitude (the `amplitude` keys of `[[force]]` tables) × level."""
    out, in_force = [], False
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("["):
            in_force = stripped == "[[force]]"
        m = _AMPLITUDE.match(line) if in_force else None
        out.append(f"{m.group(1)}{float(m.group(2)) * level!r}{m.group(3)}" if m else line)
    if not any(_AMPLITUDE.match(l) for l in out):
        raise ValueError("the scene has no [[force]] amplitude to scale")
    return "\n".join(out) + "\n"


def continue_level(cli: str, scene: str, level: float, start: float, stop: float, workdir: str) -> dict:
    """One task: the frequency branch of the scene with its forces × level."""
    with open(scene) as f:
        text = f.read()
    base = os.path.join(workdir, f"level-{level!r}")
    path = base + ".toml"
    with open(path, "w") as f:
        f.write(scaled_scene(text, level))
    out = base + ".csv"
    t0 = time.perf_counter()
    cp = subprocess.run([cli, "continue", path, "--param", "frequency", "--from", repr(start), "--to", repr(stop),
                         "-o", out, "--quiet", "--no-plot"], capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if not os.path.exists(out):
        raise RuntimeError(f"force level {level}: `periodic-contact continue` wrote no branch (exit {cp.returncode}): {cp.stderr.strip()}")
    with open(out) as f:
        rows = list(csv.DictReader(f))
    with open(base + "-events.json") as f:
        events = json.load(f)
    return {"force_scale": level, "rows": rows, "events": events["events"], "stop": events["stop"], "seconds": seconds}


def run_levels(client, cli: str, scene: str, levels: list[float], start: float, stop: float, workdir: str) -> list[dict]:
    """One task per force level on the client's cluster, results in the order of `levels`."""
    futures = [client.submit(continue_level, cli, os.path.abspath(scene), level, start, stop, workdir, pure=False) for level in levels]
    return client.gather(futures)


def write_csv(path: str, results: list[dict]) -> None:
    header = ["force_scale"] + list(results[0]["rows"][0].keys())
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in results:
            for row in r["rows"]:
                w.writerow([repr(r["force_scale"])] + [row[k] for k in header[1:]])


def plot(path: str, results: list[dict], title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 5.5))
    for i, r in enumerate(results):
        rows = r["rows"]
        keys = list(rows[0].keys())
        f_key, a_key = keys[0], next(k for k in keys if k.startswith("amplitude_"))
        colour = f"C{i % 10}"
        run, stable = [], rows[0]["stable"] == "true"
        for row in rows:
            point = (float(row[f_key]), float(row[a_key]))
            if (row["stable"] == "true") != stable:
                run.append(point)
                ax.plot(*zip(*run), color=colour, linestyle="-" if stable else "--")
                run, stable = [], not stable
            run.append(point)
        ax.plot(*zip(*run), color=colour, linestyle="-" if stable else "--", label=f"force × {r['force_scale']:g}")
        ev = [(float(row[f_key]), float(row[a_key])) for row in rows if row["event"]]
        if ev:
            ax.plot(*zip(*ev), "o", color=colour, markersize=4)
    ax.set_xlabel(f"excitation frequency ω {f_key.split(' ', 1)[1] if ' ' in f_key else ''}")
    ax.set_ylabel(f"{a_key} (peak-to-peak / 2)")
    ax.set_title(f"{title}: branches per force level (dashed: unstable; dots: events)")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scene")
    p.add_argument("--from", dest="start", type=float, required=True)
    p.add_argument("--to", dest="stop", type=float, required=True)
    p.add_argument("--levels", required=True, help="force scales, comma-separated (1 = the scene's forces)")
    cluster_arguments(p, "per-level scenes and branches", "levels.csv")
    a = p.parse_args(argv)
    try:
        levels = [float(v) for v in a.levels.split(",")]
    except ValueError:
        p.error(f"--levels: is {a.levels!r}, give numbers separated by commas, e.g. 0.5,1,2")
    if not levels or any(not (v > 0.0) for v in levels):
        p.error(f"--levels: is {a.levels!r}, every level must be > 0")
    if not os.access(a.cli, os.X_OK):
        p.error(f"--cli: {a.cli} is not an executable; build it with `cargo build --release` or set PC_CLI")
    from distributed import Client, LocalCluster

    workdir = a.workdir or tempfile.mkdtemp(prefix="pc-levels-")
    os.makedirs(workdir, exist_ok=True)
    t0 = time.perf_counter()
    if a.scheduler:
        with Client(a.scheduler) as client:
            results = run_levels(client, a.cli, a.scene, levels, a.start, a.stop, workdir)
    else:
        with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
            results = run_levels(client, a.cli, a.scene, levels, a.start, a.stop, workdir)
    write_csv(a.output, results)
    stem = os.path.splitext(a.output)[0]
    with open(stem + "-events.json", "w") as f:
        json.dump({repr(r["force_scale"]): {"stop": r["stop"], "events": r["events"]} for r in results}, f, indent=1)
    plot(stem + ".png", results, os.path.splitext(os.path.basename(a.scene))[0])
    for r in results:
        kinds = ", ".join(f"{e['type']} {e['frequency']:.6g}" for e in r["events"]) or "none"
        print(f"force × {r['force_scale']:g}: {len(r['rows'])} points in {r['seconds']:.1f} s, stop: {r['stop']}; events: {kinds}")
    print(f"{len(levels)} levels in {time.perf_counter() - t0:.1f} s wall → {a.output}, {stem}-events.json, {stem}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
