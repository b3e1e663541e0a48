"""Peers side by side, in one run (issue 6, part 2; issue 12, item 4).

    validation/.venv/bin/python validation/peers/siconos_lemke.py [--sizes 1024,2048,4096]
        [--multi-sizes 1024,2048,4096] [--random-sizes 2048] [--cases rigid,chain,compliant]
        [--seed 1] [--tol 1e-10] [--out DIR] [--cli PATH] [--siconos-timeout S]
        [--no-install] [--no-march] [--keep-lcp]

1. Cases (CASES): the rigid stop with sticking (fmu/scenes/rigid-stop.toml, k = N), the 3-DOF
   chain with two rigid stops (chain-3dof-two-stops.toml, 2 contacts, k = N/2) and the compliant
   stop (compliant-stop.toml, k = N); --random-sizes adds one random member of each family
   (frequency x U(0.95, 1.05), each gap x U(0.9, 1.1), seeded). Each scene is solved by our CLI
   with the LCP exported on the way: `periodic-contact solve SCENE --no-estimate --export-lcp
   FILE.dat` (one thread; [solver] tolerance = TOL appended to the scene). Its `timing_s.lcp` is
   our solver time on the scene (shooting on the step map first, certified on the LCP; `lcp.path`
   says which method ran) and its contact forces, interleaved per instant, are its z.
2. On the exported file: our raw `periodic-contact lcp FILE.dat --tolerance TOL` (no step map:
   block-circulant detection, block pivoting with FFT products, Lemke as the fallback; `time_s`)
   and Siconos 4.4's lexicographic Lemke (`lcp_lexicolemke`, Debian's python3-siconos, run with
   /usr/bin/python3 in a subprocess: siconos_worker.py, the call alone timed). The worker checks
   all three z on the same (M, q) by the same numpy measure ||min(z, Mz+q)||_inf <= TOL max(1,
   ||q||_inf) (our CLI's certificate) and Siconos' lcp_compute_error, and compares them. The .dat
   files are deleted after use unless --keep-lcp (N = 4096 is ~390 MB).
3. Time marching to the steady state "the same way" (rigid stop only): the scipy/numpy
   central-difference marcher of validation/marching (march_cds, forward-increment multipliers, N
   steps per period, from rest until the periodicity defect < 1e-10) against our whole periodic
   solve (CLI `solve`, k = N, timing_s.total).

python3-siconos is installed with apt-get when absent (apt-cache policy first, apt-get update once
if no candidate is known); when it cannot be installed the Siconos part is skipped with the reason
(the numpy check still runs). Writes DIR/peers.md (the tables) and DIR/peers.json.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
VALIDATION = os.path.dirname(HERE)
ROOT = os.path.dirname(VALIDATION)
if VALIDATION not in sys.path:
    sys.path.insert(0, VALIDATION)

SYSTEM_PYTHON = "/usr/bin/python3"
RIGID_SCENE = os.path.join(ROOT, "fmu", "scenes", "rigid-stop.toml")


def cli_path() -> str:
    p = os.environ.get("PC_CLI") or os.path.join(ROOT, "target", "release", "periodic-contact")
    return os.path.abspath(p)


def _run(cmd, timeout=3600, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)


# --------------------------------------------------------------------------- Siconos availability

def siconos_importable(python: str = SYSTEM_PYTHON) -> bool:
    if not os.path.exists(python):
        return False
    cp = _run([python, "-c", "import siconos.numerics as sn; sn.lcp_lexicolemke; sn.SICONOS_LCP_LEMKE"], timeout=120)
    return cp.returncode == 0


def _candidate() -> str | None:
    """The candidate version of python3-siconos known to apt, or None."""
    if not shutil.which("apt-cache"):
        return None
    cp = _run(["apt-cache", "policy", "python3-siconos"], timeout=120)
    for line in cp.stdout.splitlines():
        line = line.strip()
        if line.startswith("Candidate:"):
            v = line.split(":", 1)[1].strip()
            return None if v in ("", "(none)") else v
    return None


def ensure_siconos(install: bool = True, log=print) -> tuple[bool, str]:
    """(available, message). Installs Debian's python3-siconos with apt-get when absent."""
    if siconos_importable():
        return True, f"siconos found in {SYSTEM_PYTHON}"
    if not install:
        return False, "python3-siconos is not installed and --no-install was given"
    if not shutil.which("apt-get"):
        return False, "python3-siconos is not installed and apt-get is not available (not a Debian system?)"
    if hasattr(os, "geteuid") and os.geteuid() != 0:
        return False, "python3-siconos is not installed and installing it needs root (apt-get)"
    cand = _candidate()
    if cand is None:
        log("apt-cache knows no python3-siconos candidate: running apt-get update once")
        cp = _run(["apt-get", "update"], timeout=900)
        if cp.returncode != 0:
            return False, f"apt-get update failed: {cp.stderr.strip()[-500:]}"
        cand = _candidate()
        if cand is None:
            return False, "no python3-siconos package in the configured apt sources (Debian bookworm has 4.4.0+dfsg-2)"
    log(f"installing python3-siconos {cand} with apt-get")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    cp = _run(["apt-get", "install", "-y", "python3-siconos"], timeout=1800, env=env)
    if cp.returncode != 0 and "held broken packages" in (cp.stdout + cp.stderr):
        # Stale package lists (dependencies moved on): refresh once and retry.
        log("apt-get install failed on stale package lists: apt-get update, then retry")
        _run(["apt-get", "update"], timeout=900)
        cp = _run(["apt-get", "install", "-y", "python3-siconos"], timeout=1800, env=env)
    if cp.returncode != 0:
        return False, f"apt-get install -y python3-siconos failed: {(cp.stdout + cp.stderr).strip()[-800:]}"
    if not siconos_importable():
        return False, f"python3-siconos {cand} installed but `import siconos.numerics` fails in {SYSTEM_PYTHON}"
    return True, f"python3-siconos {cand} installed"


# --------------------------------------------------------------------------- the cases

# Each case: the shipped scene, the `steps = ...` line it ships with, the contacts m (N = k m),
# and its family: the parameters a random member varies (uniformly, relative) -- frequency and
# gap(s), a few per cent, so the regime (sticking, two stops, compliant contact) stays the same.
CASES = {
    "rigid": {"scene": "rigid-stop.toml", "steps_line": "steps = 256", "m": 1,
              "what": "rigid stop with sticking (src/formulation.md §6.3; cds, forward pairing; 1 contact, k = N)"},
    "chain": {"scene": "chain-3dof-two-stops.toml", "steps_line": "steps = 256", "m": 2,
              "what": "3-DOF chain with two rigid stops (cds, forward pairing; 2 contacts, k = N/2)"},
    "compliant": {"scene": "compliant-stop.toml", "steps_line": "steps = 512", "m": 1,
                  "what": "compliant stop (src/formulation.md §6.2; cds, same-instant pairing; 1 contact, k = N)"},
}
FREQUENCY_SPREAD = 0.05  # a random member's frequency: nominal x U(1 - 0.05, 1 + 0.05)
GAP_SPREAD = 0.10  # each gap: nominal x U(1 - 0.10, 1 + 0.10)


def scene_text(case: str, n: int, tol: float, draw: int = 0, seed: int = 1) -> tuple[str, str]:
    """(TOML text, label) of the case at LCP size n; draw > 0: a random member of its family."""
    import random

    spec = CASES[case]
    path = os.path.join(ROOT, "fmu", "scenes", spec["scene"])
    with open(path) as f:
        text = f.read()
    if n % spec["m"]:
        raise ValueError(f"{case}: N = {n} is not a multiple of its {spec['m']} contacts")
    if text.count(spec["steps_line"]) != 1 or "[solver]" in text:
        raise RuntimeError(f"{path}: expected one '{spec['steps_line']}' and no [solver] section")
    text = text.replace(spec["steps_line"], f"steps = {n // spec['m']}")
    # The CLI's certificate (relative to max(1, ||q||)) at the comparison's tolerance.
    text += f"\n[solver]\ntolerance = {tol!r}\n"
    if draw == 0:
        return text, "nominal"
    rng = random.Random(f"{seed}-{case}-{draw}")
    label = []

    def scale(key, spread):
        def sub(mo):
            v = float(mo.group(2)) * rng.uniform(1 - spread, 1 + spread)
            label.append(f"{key} {v:.4g}")
            return f"{mo.group(1)}{v!r}"
        return sub

    text, nf = re.subn(r"(?m)^(frequency = )([0-9.eE+-]+)$", scale("frequency", FREQUENCY_SPREAD), text)
    text, ng = re.subn(r"(?m)^(gap = )([0-9.eE+-]+)$", scale("gap", GAP_SPREAD), text)
    if nf != 1 or ng != spec["m"]:
        raise RuntimeError(f"{path}: expected 1 frequency and {spec['m']} gap lines, found {nf} and {ng}")
    return text, f"random (seed {seed}): " + ", ".join(label)


# --------------------------------------------------------------------------- our side

ONE_THREAD = dict(os.environ, RAYON_NUM_THREADS="1")  # Siconos' Lemke runs on one core too


def ours_solve_export(cli: str, scene: str, dat: str, out_json: str) -> dict:
    """`periodic-contact solve SCENE --export-lcp DAT`: the scene's own path (shooting first)."""
    cmd = [cli, "solve", scene, "-o", out_json, "--no-estimate", "--export-lcp", dat]
    cp = _run(cmd, env=ONE_THREAD)
    if cp.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {cp.returncode}: {cp.stderr[-2000:]}")
    with open(out_json) as f:
        return json.load(f)


def solve_z(r: dict) -> list[float]:
    """The solve's contact forces interleaved per instant, z[j m + a] = force of contact a at
    sample j: the order of the exported LCP (PeriodicProblem::lcp, response recovery)."""
    forces = [c["force"] for c in r["contacts"]]
    return [f[j] for j in range(len(forces[0])) for f in forces]


def ours_lcp(cli: str, dat: str, tol: float, out_json: str) -> dict:
    cmd = [cli, "lcp", dat, "-o", out_json, "--tolerance", repr(tol)]
    t0 = time.perf_counter()
    cp = _run(cmd, env=ONE_THREAD)
    wall = time.perf_counter() - t0
    if cp.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)}: exit {cp.returncode}: {cp.stderr[-2000:]}")
    with open(out_json) as f:
        r = json.load(f)
    r["process_wall_s"] = wall
    return r


def check_and_siconos(dat: str, tol: float, candidates: dict, out_json: str, with_siconos: bool, timeout: float) -> dict:
    """siconos_worker.py: Siconos' Lemke (when available) and the numpy check of every z."""
    cand = out_json.replace(".json", "-candidates.json")
    with open(cand, "w") as f:
        json.dump(candidates, f)
    python = SYSTEM_PYTHON if with_siconos else sys.executable
    cmd = [python, os.path.join(HERE, "siconos_worker.py"), dat, repr(tol), cand, out_json] + ([] if with_siconos else ["--no-siconos"])
    try:
        cp = _run(cmd, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"timeout_s": timeout}
    finally:
        os.remove(cand)
    if cp.returncode != 0:
        raise RuntimeError(f"siconos worker failed: {' '.join(cmd)}\n{cp.stderr[-3000:]}")
    with open(out_json) as f:
        return json.load(f)


def short_path(path: str) -> str:
    """`lcp.path` of the solve JSON in a few words: the methods tried and how each ended."""
    tail = path.split("):", 1)[-1]
    parts = []
    for step in tail.split(";"):
        step = step.strip().removeprefix("fallback:").strip()
        method = step.split("(")[0].split(",")[0].strip()
        outcome = step.rsplit("→", 1)[-1].strip() if "→" in step else "?"
        parts.append(f"{method} → {outcome}")
    return "; ".join(parts)


# --------------------------------------------------------------------------- time marching

def rigid_system():
    from marching.model import Contact, Force, System

    # src/formulation.md §6.3: m = 1, c = 0.1, k = 1, F = 1 cos t, rigid stop x <= 0.5 (fmu/scenes/rigid-stop.toml)
    return System.build([[1.0]], [[1.0]], 1.0, forces=[Force(0, 1.0)], contacts=[Contact(0, 0.5)], damping=[[0.1]])


def ours_solve(cli: str, n: int, out: str) -> dict:
    with open(RIGID_SCENE) as f:
        text = f.read()
    if "steps = 256" not in text:
        raise RuntimeError(f"{RIGID_SCENE}: expected 'steps = 256' to replace")
    scene = os.path.join(out, f"rigid-stop-k{n}.toml")
    with open(scene, "w") as f:
        f.write(text.replace("steps = 256", f"steps = {n}"))
    res = os.path.join(out, f"rigid-stop-k{n}.json")
    cp = _run([cli, "solve", scene, "-o", res], env=dict(os.environ, RAYON_NUM_THREADS="1"))
    if cp.returncode != 0:
        raise RuntimeError(f"solve failed: {cp.stderr[-2000:]}")
    with open(res) as f:
        return json.load(f)


def march(n: int) -> dict:
    import numpy as np

    from marching.central_difference import march_cds

    r = march_cds(rigid_system(), n, pairing="forward", tol=1e-10)
    return {"cpu_s": r.cpu_time, "periods": r.periods, "x": np.asarray(r.x[0]), "impulse": float(r.impulse[0])}


# --------------------------------------------------------------------------- report

def fmt(v, spec=".2e"):
    return "—" if v is None else format(v, spec)


def markdown(res: dict) -> str:
    s = ["# Peers side by side (generated by `validation/peers/siconos_lemke.py`)", ""]
    s.append(f"Machine: {platform.machine()}, {os.cpu_count()} cores, load average at the start {res['load'][0]} and the end "
             f"{res['load'][1]}. Tolerance: {res['tol']:g}, relative to max(1, ‖q‖∞), for every solution. Cases:")
    s.append("")
    for name, spec in CASES.items():
        s.append(f"- **{name}**: `fmu/scenes/{spec['scene']}`, {spec['what']}.")
    s.append("")
    sic_ok = res["siconos"]["available"]
    s.append((f"Siconos: {res['siconos']['message']}; `lcp_lexicolemke` (dense tableau, pivot budget 20 N + 100) timed around the "
              "call only." if sic_ok else f"**Siconos skipped**: {res['siconos']['message']}.")
             + " Ours, one thread: `solve` = `periodic-contact solve SCENE` (`timing_s.lcp`, the LCP solve of the scene, "
             "shooting on the step map first, certified on the LCP, with its fallback); `lcp` = `periodic-contact lcp FILE.dat` "
             "on the exported LCP (no step map: block-circulant detection + block pivoting + Lemke; `time_s`, reading "
             "excluded). Ratio = Siconos time / ours. Residual = ‖min(z, Mz + q)‖∞ / max(1, ‖q‖∞) of each z on the exported "
             "(M, q), the same numpy check for all; ✗ = above the tolerance. Δz = ‖z − z_Siconos‖∞ / max(1, ‖z_Siconos‖∞).")
    s.append("")
    s.append("| case | member | N (k×m) | Siconos [s] | Siconos pivots | ours solve [s] | solve path | ours lcp [s] | lcp pivots | "
             "ratio S/solve | ratio S/lcp | residual Siconos | residual solve | residual lcp | Siconos lcp_compute_error | Δz solve | Δz lcp | ‖z_solve − z_lcp‖ |")
    s.append("|---|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")

    def res_cell(c):
        if not c:
            return "—"
        return fmt(c["residual_rel"]) + ("" if c["certified"] else " ✗")

    for row in ordered(res["lcp"]):
        w = row.get("check") or {}
        sic = w.get("siconos") or {}
        ch = w.get("checks", {})
        d = w.get("differences", {})
        timeout = w.get("timeout_s")
        sic_time = f"> {timeout:.0f} (stopped)" if timeout else fmt(sic.get("time_s"), ".3f")
        s.append(f"| {row['case']} | {row['member']} | {row['n']} ({row['k']}×{row['m']}) | {sic_time} | {sic.get('pivots', '—')} | "
                 f"{row['solve']['time_s']:.4f} | {row['solve']['path']} | {row['lcp']['time_s']:.4f} | {row['lcp']['pivots']} | "
                 f"{fmt(row.get('ratio_solve'), '.0f')}× | {fmt(row.get('ratio_lcp'), '.1f')}× | {res_cell(ch.get('siconos'))} | "
                 f"{res_cell(ch.get('solve'))} | {res_cell(ch.get('lcp'))} | {fmt(sic.get('lcp_compute_error'))} | "
                 f"{fmt(d.get('siconos-solve'))} | {fmt(d.get('siconos-lcp'))} | {fmt(d.get('solve-lcp'))} |")
    if res.get("march"):
        s.append("")
        s.append("## Time marching to the steady state against the periodic LCP (rigid stop, N steps per period = k)")
        s.append("")
        s.append("scipy/numpy central differences with forward-increment multipliers (`validation/marching/central_difference.py`, "
                 "from rest until the periodicity defect < 1e-10; `time.process_time`) against our whole solve "
                 "(`periodic-contact solve`, k = N, one thread, `timing_s.total` = assembly + LCP + recovery). Both compute "
                 "the same discrete orbit (the steady state of the marcher is the cds/forward periodic solution).")
        s.append("")
        s.append("| N | marching CPU [s] | periods | ours total [s] | ratio marching/ours | ‖x_march − x_ours‖∞ / peak-to-peak |")
        s.append("|---:|---:|---:|---:|---:|---:|")
        for m in res["march"]:
            s.append(f"| {m['n']} | {m['march_cpu_s']:.3f} | {m['periods']} | {m['ours_total_s']:.4f} | {m['ratio']:.1f}× | {m['difference']:.1e} |")
    s.append("")
    return "\n".join(s)


def ordered(rows: list[dict]) -> list[dict]:
    """By case and N; within a family at one N, worst first (the smallest ratio Siconos/solve)."""
    order = {c: i for i, c in enumerate(CASES)}
    return sorted(rows, key=lambda r: (order[r["case"]], r["n"], r.get("ratio_solve") or 0.0))


def load_average() -> str:
    try:
        return open("/proc/loadavg").read().split()[0]
    except OSError:
        return "unknown"


def plan(sizes: list[int], multi_sizes: list[int], random_sizes: list[int], cases: list[str]) -> list[tuple[str, int, int]]:
    """(case, N, draw) to run: rigid at `sizes`, chain and compliant at `multi_sizes`, one random
    member of each selected family at `random_sizes`."""
    todo = []
    for case in cases:
        if case not in CASES:
            raise ValueError(f"unknown case {case!r}: expected some of {', '.join(CASES)}")
        for n in sizes if case == "rigid" else multi_sizes:
            todo.append((case, n, 0))
        for n in random_sizes:
            todo.append((case, n, 1))
    return todo


def run(sizes: list[int], tol: float, out: str, cli: str | None = None, install: bool = True, do_march: bool = True,
        log=print, keep_lcp: bool = False, multi_sizes: list[int] | None = None, random_sizes: list[int] | None = None,
        cases: list[str] | None = None, seed: int = 1, siconos_timeout: float = 3600.0) -> dict:
    cli = cli or cli_path()
    if not os.access(cli, os.X_OK):
        raise RuntimeError(f"periodic-contact CLI not found at {cli} (build it: cargo build --release, or set PC_CLI)")
    os.makedirs(out, exist_ok=True)
    cases = cases or list(CASES)
    todo = plan(sizes, multi_sizes or [], random_sizes or [], cases)
    res: dict = {"tol": tol, "sizes": sizes, "multi_sizes": multi_sizes, "random_sizes": random_sizes, "seed": seed,
                 "load": [load_average(), None], "lcp": [], "march": []}
    available, message = ensure_siconos(install, log)
    res["siconos"] = {"available": available, "message": message}
    log(("Siconos: " if available else "Siconos skipped: ") + message)
    for case, n, draw in todo:
        m = CASES[case]["m"]
        tag = f"{case}-N{n}" + (f"-r{draw}" if draw else "")
        text, member = scene_text(case, n, tol, draw, seed)
        scene = os.path.join(out, f"{tag}.toml")
        with open(scene, "w") as f:
            f.write(text)
        dat = os.path.join(out, f"{tag}.dat")
        solve = ours_solve_export(cli, scene, dat, os.path.join(out, f"{tag}-solve.json"))
        lcp = ours_lcp(cli, dat, tol, os.path.join(out, f"{tag}-lcp.json"))
        row = {"case": case, "member": member, "n": n, "k": n // m, "m": m,
               "solve": {"time_s": solve["timing_s"]["lcp"], "path": short_path(solve["lcp"]["path"]), "full_path": solve["lcp"]["path"],
                         "status": solve["lcp"]["status"], "pivots": solve["lcp"]["pivots"], "residual": solve["lcp"]["residual"]},
               "lcp": {k: lcp[k] for k in ("status", "structure", "pivots", "residual", "time_s", "detect_time_s", "solve_time_s", "process_wall_s")}}
        log(f"{tag} ({member}): solve {row['solve']['time_s']:.4f} s [{row['solve']['path']}], lcp {lcp['status']} in {lcp['time_s']:.4f} s "
            f"({lcp['pivots']} pivots, {lcp['structure']})")
        w = check_and_siconos(dat, tol, {"solve": solve_z(solve), "lcp": lcp["z"]}, os.path.join(out, f"{tag}-check.json"), available, siconos_timeout)
        row["check"] = w
        sic = w.get("siconos")
        if sic:
            row["ratio_solve"] = sic["time_s"] / max(row["solve"]["time_s"], 1e-9)
            row["ratio_lcp"] = sic["time_s"] / max(lcp["time_s"], 1e-9)
            log(f"{tag}: Siconos info {sic['info']} in {sic['time_s']:.3f} s ({sic['pivots']} pivots, error {sic['lcp_compute_error']:.2e}); "
                f"ratio {row['ratio_solve']:.0f}x (solve), {row['ratio_lcp']:.1f}x (lcp)")
        elif w.get("timeout_s"):
            row["ratio_solve"] = w["timeout_s"] / max(row["solve"]["time_s"], 1e-9)  # a lower bound
            log(f"{tag}: Siconos stopped after {w['timeout_s']:.0f} s")
        res["lcp"].append(row)
        if not keep_lcp and os.path.exists(dat):
            os.remove(dat)  # N = 4096 is ~390 MB of text
    if do_march and "rigid" in cases:
        import numpy as np

        for n in sizes:
            r = ours_solve(cli, n, out)
            m = march(n)
            x_ours = np.asarray(r["displacement"]["0"])
            ptp = float(np.ptp(x_ours))
            diff = float(np.max(np.abs(m["x"] - x_ours))) / ptp
            total = r["timing_s"]["total"]
            res["march"].append({"n": n, "march_cpu_s": m["cpu_s"], "periods": m["periods"], "ours_total_s": total,
                                 "ratio": m["cpu_s"] / total, "difference": diff})
            log(f"N = {n}: marching {m['cpu_s']:.3f} s ({m['periods']} periods), ours {total:.4f} s, difference {diff:.1e}")
    res["load"][1] = load_average()
    with open(os.path.join(out, "peers.json"), "w") as f:
        json.dump(res, f, indent=2, default=str)
    with open(os.path.join(out, "peers.md"), "w") as f:
        f.write(markdown(res))
    return res


def sizes_arg(text: str) -> list[int]:
    return [int(v) for v in text.split(",") if v.strip()]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="1024,2048,4096", help="N of the rigid stop (and of the marching comparison)")
    ap.add_argument("--multi-sizes", default="1024,2048,4096", help="N of the chain and the compliant stop (chain: k = N/2)")
    ap.add_argument("--random-sizes", default="2048", help="N of one random member of each family ('' for none)")
    ap.add_argument("--cases", default=",".join(CASES), help="some of " + ", ".join(CASES))
    ap.add_argument("--seed", type=int, default=1, help="seed of the random members")
    ap.add_argument("--tol", type=float, default=1e-10)
    ap.add_argument("--out", default=os.path.join(HERE, "out"))
    ap.add_argument("--cli", default=None)
    ap.add_argument("--siconos-timeout", type=float, default=3600.0, help="seconds after which one Siconos run is stopped")
    ap.add_argument("--no-install", action="store_true")
    ap.add_argument("--no-march", action="store_true")
    ap.add_argument("--keep-lcp", action="store_true", help="keep the exported .dat files (N = 4096: ~390 MB)")
    a = ap.parse_args(argv)
    res = run(sizes_arg(a.sizes), a.tol, a.out, a.cli, not a.no_install, not a.no_march, keep_lcp=a.keep_lcp,
              multi_sizes=sizes_arg(a.multi_sizes), random_sizes=sizes_arg(a.random_sizes), cases=[c for c in a.cases.split(",") if c],
              seed=a.seed, siconos_timeout=a.siconos_timeout)
    print(markdown(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
