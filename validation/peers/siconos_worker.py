"""Siconos side of the peers comparison, and the one numpy check every solution goes through.

    /usr/bin/python3 siconos_worker.py LCP.dat TOL CANDIDATES.json OUT.json [--no-siconos]

Run with the interpreter that has Debian's python3-siconos (/usr/bin/python3), not the
validation venv; with --no-siconos (Siconos unavailable) only the numpy check runs, and any
Python with numpy will do.

Reads the dense Siconos .dat LCP (M stored column by column: line j of the matrix block is
column j of M, as Siconos' own reader does), times Siconos' lexicographic Lemke
(`lcp_lexicolemke`, the call only) with the pivot budget 20 N + 100 (ours), then checks every
solution -- Siconos' and each named z of CANDIDATES.json ({"name": [z...]}, e.g. our `lcp` and
our `solve`) -- on the same (M, q) by the same measure: ||min(z, Mz + q)||_inf, certified when
<= TOL max(1, ||q||_inf) (our CLI's certificate), plus Siconos' lcp_compute_error when Siconos is
there. Also the pairwise differences of the solutions. Writes OUT.json.
"""
from __future__ import annotations

import json
import sys
import time

import numpy as np


def read_dat(path: str):
    with open(path) as f:
        n = int(f.readline())
        storage = int(f.readline())
        if storage != 0:
            raise ValueError(f"{path}: storage type {storage}, only dense (0) is supported")
        rows, cols = int(f.readline()), int(f.readline())
        f.readline()  # "n<TAB>n"
        if rows != n or cols != n:
            raise ValueError(f"{path}: {rows}x{cols} matrix for size {n}")
        cols_data = np.empty((n, n))
        for j in range(n):
            line = f.readline()
            while not line.strip():
                line = f.readline()
            cols_data[j] = np.array(line.split(), dtype=float)
        line = f.readline()
        while not line.strip():
            line = f.readline()
        q = np.array(line.split(), dtype=float)
    # cols_data[j] is column j: M = cols_data^T, kept Fortran-ordered (Siconos is column-major).
    return np.asfortranarray(cols_data.T), q


def residual_inf(M, q, z) -> float:
    """||min(z, Mz + q)||_inf: zero exactly when z >= 0, w >= 0 and z.w = 0 (the natural residual)."""
    w = M @ z + q
    return float(np.max(np.abs(np.minimum(z, w)))) if z.size else 0.0


def check(M, q, z, tol: float) -> dict:
    scale = max(1.0, float(np.max(np.abs(q)))) if q.size else 1.0
    r = residual_inf(M, q, z)
    return {"residual_inf": r, "residual_rel": r / scale, "certified": bool(np.all(np.isfinite(z)) and r <= tol * scale)}


def main() -> int:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    with_siconos = "--no-siconos" not in sys.argv
    dat, tol, cand_path, out_path = args[0], float(args[1]), args[2], args[3]
    M, q = read_dat(dat)
    n = q.size
    with open(cand_path) as f:
        zs = {name: np.array(z, dtype=float) for name, z in json.load(f).items()}
    for name, z in zs.items():
        if z.shape != (n,):
            raise ValueError(f"{cand_path}: z of '{name}' has {z.size} entries for an LCP of size {n}")
    out: dict = {"size": n, "q_inf": float(np.max(np.abs(q))), "tol": tol}
    if with_siconos:
        import siconos.numerics as sn

        lcp = sn.LCP(M, q)
        so = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
        so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = 20 * n + 100
        so.dparam[sn.SICONOS_DPARAM_TOL] = tol
        z = np.zeros(n)
        w = np.zeros(n)
        t0 = time.perf_counter()
        info = sn.lcp_lexicolemke(lcp, z, w, so)
        t_sic = time.perf_counter() - t0
        err_sic = float(sn.lcp_compute_error(lcp, z, np.zeros(n), tol))
        out["siconos"] = {
            "info": int(info),
            "pivots": int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
            "time_s": t_sic,
            "lcp_compute_error": err_sic,
            "solved": bool(info == 0 and err_sic <= tol),
        }
        out["siconos_version"] = str(getattr(__import__("siconos"), "__version__", "4.4 (Debian python3-siconos)"))
        zs = {"siconos": z, **zs}
    checks = {}
    for name, z in zs.items():
        c = check(M, q, z, tol)
        if with_siconos:
            c["lcp_compute_error"] = float(sn.lcp_compute_error(lcp, z, np.zeros(n), tol))
        checks[name] = c
    out["checks"] = checks
    # ||z_a - z_b||_inf / max(1, ||z_a||_inf) for every pair (a before b in the order above).
    names = list(zs)
    out["differences"] = {
        f"{a}-{b}": float(np.max(np.abs(zs[a] - zs[b]))) / max(1.0, float(np.max(np.abs(zs[a]))))
        for i, a in enumerate(names) for b in names[i + 1:]
    }
    with open(out_path, "w") as f:
        json.dump(out, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
