"""Peers side by side, in one run (issue 6, part 2).

    validation/.venv/bin/python validation/peers/siconos_lemke.py [--sizes 1024,2048,4096]
        [--tol 1e-10] [--out DIR] [--cli PATH] [--no-install] [--no-march]

1. Exports the rigid-stop LCPs of the accuracy study (notes §6.3, cds with forward pairing;
   k = N) in Siconos' dense .dat format through the CLI:
   `periodic-contact study accuracy --cases rigid --methods cds/forward --steps N,... --no-march
   --export-lcp DIR`.
2. On each file, in the same run: our CLI `periodic-contact lcp FILE.dat --tolerance TOL`
   (method auto: it detects the block-circulant structure and takes the fast path) and Siconos
   4.4's lexicographic Lemke (`lcp_lexicolemke`, Debian's python3-siconos, run with
   /usr/bin/python3 in a subprocess: siconos_worker.py). The .dat files are deleted after use
   unless --keep-lcp (N = 4096 is ~390 MB). Same tolerance for both (TOL:
   our certification ||min(z, Az+q)||_inf <= TOL max(1, ||q||_inf); Siconos' lcp_compute_error
   <= TOL). Both solutions are checked on the same data by the same two measures.
   Times: our JSON's time_s (structure detection + solve; reading the file excluded) against the
   lcp_lexicolemke call alone.
3. Time marching to the steady state "the same way": the scipy/numpy central-difference marcher
   of validation/marching (march_cds, forward-increment multipliers, N steps per period, from rest
   until the periodicity defect < 1e-10) against our whole periodic solve (CLI `solve`, k = N,
   timing_s.total), on the same rigid stop.

python3-siconos is installed with apt-get when absent (apt-cache policy first, apt-get update once
if no candidate is known); when it cannot be installed the Siconos part is skipped with the reason.
Writes DIR/peers.md (the tables) and DIR/peers.json.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
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


# --------------------------------------------------------------------------- our side

def export_lcps(cli: str, sizes: list[int], out: str) -> dict[int, str]:
    lcp_dir = os.path.join(out, "lcp")
    os.makedirs(lcp_dir, exist_ok=True)
    cmd = [cli, "study", "accuracy", "-o", os.path.join(out, "export-study"), "--cases", "rigid", "--methods", "cds/forward",
           "--steps", ",".join(map(str, sizes)), "--no-march", "--export-lcp", lcp_dir, "--export-max", str(max(sizes))]
    cp = _run(cmd)
    if cp.returncode != 0:
        raise RuntimeError(f"export failed: {' '.join(cmd)}\n{cp.stderr[-3000:]}")
    files = {}
    for n in sizes:
        p = os.path.join(lcp_dir, f"rigid-cds-forward-k{n}.dat")
        if not os.path.exists(p):
            raise RuntimeError(f"export did not write {p}")
        files[n] = p
    return files


def ours_lcp(cli: str, dat: str, tol: float, out_json: str) -> dict:
    cmd = [cli, "lcp", dat, "-o", out_json, "--tolerance", repr(tol)]
    t0 = time.perf_counter()
    cp = _run(cmd)
    wall = time.perf_counter() - t0
    if cp.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)}: exit {cp.returncode}: {cp.stderr[-2000:]}")
    with open(out_json) as f:
        r = json.load(f)
    r["process_wall_s"] = wall
    return r


def siconos_lcp(dat: str, tol: float, ours_json: str, out_json: str) -> dict:
    cmd = [SYSTEM_PYTHON, os.path.join(HERE, "siconos_worker.py"), dat, repr(tol), ours_json, out_json]
    cp = _run(cmd, timeout=7200)
    if cp.returncode != 0:
        raise RuntimeError(f"siconos worker failed: {' '.join(cmd)}\n{cp.stderr[-3000:]}")
    with open(out_json) as f:
        return json.load(f)


# --------------------------------------------------------------------------- time marching

def rigid_system():
    from marching.model import Contact, Force, System

    # notes §6.3: m = 1, c = 0.1, k = 1, F = 1 cos t, rigid stop x <= 0.5 (fmu/scenes/rigid-stop.toml)
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
             f"{res['load'][1]}. Tolerance for both LCP solvers: {res['tol']:g}. LCPs: the rigid stop of notes §6.3 "
             "(cds, forward pairing, k = N, 1 contact), exported by `periodic-contact study accuracy --export-lcp`.")
    s.append("")
    if res["siconos"]["available"]:
        s.append(f"Siconos: {res['siconos']['message']}; `lcp_lexicolemke` (dense tableau, pivot budget 20 N + 100), "
                 "timed around the call only. Ours: `periodic-contact lcp FILE.dat --tolerance TOL` (`auto`: block-circulant "
                 "structure detected, then block pivoting with FFT products), `time_s` = detection + solve, file reading excluded.")
        s.append("")
        s.append("| N | Siconos Lemke [s] | Siconos pivots | ours [s] | our pivots | ratio Siconos/ours | residual ‖min(z,w)‖∞ Siconos | residual ours | lcp_compute_error Siconos | lcp_compute_error ours | ‖z_S − z_ours‖∞ / max(1, ‖z_S‖∞) |")
        s.append("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for row in res["lcp"]:
            sic = row.get("siconos") or {}
            si = sic.get("siconos", {})
            oc = sic.get("ours_checked_by_siconos", {})
            ratio = row.get("ratio")
            s.append(f"| {row['n']} | {fmt(si.get('time_s'), '.3f')} | {si.get('pivots', '—')} | {fmt(row['ours']['time_s'], '.4f')} | "
                     f"{row['ours']['pivots']} | {fmt(ratio, '.1f')}× | {fmt(si.get('residual_inf'))} | {fmt(oc.get('residual_inf'))} | "
                     f"{fmt(si.get('lcp_compute_error'))} | {fmt(oc.get('lcp_compute_error'))} | {fmt(sic.get('max_z_difference_rel'))} |")
    else:
        s.append(f"**Siconos skipped**: {res['siconos']['message']}.")
        s.append("")
        s.append("| N | ours [s] | our pivots | our residual ‖min(z,w)‖∞ | status |")
        s.append("|---:|---:|---:|---:|---|")
        for row in res["lcp"]:
            o = row["ours"]
            s.append(f"| {row['n']} | {o['time_s']:.4f} | {o['pivots']} | {o['residual']:.2e} | {o['status']} |")
    if res.get("march"):
        s.append("")
        s.append("## Time marching to the steady state against the periodic LCP (same rigid stop, N steps per period = k)")
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


def load_average() -> str:
    try:
        return open("/proc/loadavg").read().split()[0]
    except OSError:
        return "unknown"


def run(sizes: list[int], tol: float, out: str, cli: str | None = None, install: bool = True, do_march: bool = True,
        log=print, keep_lcp: bool = False) -> dict:
    cli = cli or cli_path()
    if not os.access(cli, os.X_OK):
        raise RuntimeError(f"periodic-contact CLI not found at {cli} (build it: cargo build --release, or set PC_CLI)")
    os.makedirs(out, exist_ok=True)
    res: dict = {"tol": tol, "sizes": sizes, "load": [load_average(), None], "lcp": [], "march": []}
    available, message = ensure_siconos(install, log)
    res["siconos"] = {"available": available, "message": message}
    log(("Siconos: " if available else "Siconos skipped: ") + message)
    log(f"exporting the rigid-stop LCPs N = {sizes}")
    files = export_lcps(cli, sizes, out)
    for n in sizes:
        dat = files[n]
        ours_json = os.path.join(out, f"ours-{n}.json")
        ours = ours_lcp(cli, dat, tol, ours_json)
        row = {"n": n, "file": dat, "ours": {k: ours[k] for k in ("status", "structure", "pivots", "residual", "relative_error", "time_s", "detect_time_s", "solve_time_s", "process_wall_s")}}
        log(f"N = {n}: ours {ours['status']} in {ours['time_s']:.4f} s ({ours['pivots']} pivots, residual {ours['residual']:.2e}, {ours['structure']})")
        if available:
            sic = siconos_lcp(dat, tol, ours_json, os.path.join(out, f"siconos-{n}.json"))
            row["siconos"] = sic
            row["ratio"] = sic["siconos"]["time_s"] / ours["time_s"]
            log(f"N = {n}: Siconos info {sic['siconos']['info']} in {sic['siconos']['time_s']:.3f} s ({sic['siconos']['pivots']} pivots, "
                f"residual {sic['siconos']['residual_inf']:.2e}); ratio {row['ratio']:.1f}x")
        res["lcp"].append(row)
        if not keep_lcp:
            os.remove(dat)  # N = 4096 is ~390 MB of text
    if do_march:
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="1024,2048,4096")
    ap.add_argument("--tol", type=float, default=1e-10)
    ap.add_argument("--out", default=os.path.join(HERE, "out"))
    ap.add_argument("--cli", default=None)
    ap.add_argument("--no-install", action="store_true")
    ap.add_argument("--no-march", action="store_true")
    ap.add_argument("--keep-lcp", action="store_true", help="keep the exported .dat files (N = 4096: ~390 MB)")
    a = ap.parse_args(argv)
    sizes = [int(s) for s in a.sizes.split(",") if s]
    res = run(sizes, a.tol, a.out, a.cli, not a.no_install, not a.no_march, keep_lcp=a.keep_lcp)
    print(markdown(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
