"""Siconos side of the peers comparison, run with the interpreter that has Debian's
python3-siconos (/usr/bin/python3), not the validation venv.

    /usr/bin/python3 siconos_worker.py LCP.dat TOL OURS.json OUT.json

Reads the dense Siconos .dat LCP (M stored column by column: line j of the matrix block is
column j of M, as Siconos' own reader does), times Siconos' lexicographic Lemke
(`lcp_lexicolemke`, the call only) with the pivot budget 20 N + 100 (ours), and evaluates both
solutions (Siconos' and ours, read from OURS.json's "z") on the same data with the same two
measures: ||min(z, Mz + q)||_inf and Siconos' lcp_compute_error. Writes OUT.json.
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
    w = M @ z + q
    return float(np.max(np.abs(np.minimum(z, w)))) if z.size else 0.0


def main() -> int:
    dat, tol, ours_path, out_path = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4]
    import siconos.numerics as sn

    M, q = read_dat(dat)
    n = q.size
    lcp = sn.LCP(M, q)
    so = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
    so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = 20 * n + 100
    so.dparam[sn.SICONOS_DPARAM_TOL] = tol
    z = np.zeros(n)
    w = np.zeros(n)
    t0 = time.perf_counter()
    info = sn.lcp_lexicolemke(lcp, z, w, so)
    t_sic = time.perf_counter() - t0
    pivots = int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE])
    err_sic = float(sn.lcp_compute_error(lcp, z, np.zeros(n), tol))
    res_sic = residual_inf(M, q, z)

    with open(ours_path) as f:
        ours = json.load(f)
    zo = np.array(ours["z"], dtype=float)
    err_ours = float(sn.lcp_compute_error(lcp, zo, np.zeros(n), tol))
    res_ours = residual_inf(M, q, zo)
    zscale = max(1.0, float(np.max(np.abs(z))))
    out = {
        "size": n,
        "siconos": {
            "info": int(info),
            "pivots": pivots,
            "time_s": t_sic,
            "residual_inf": res_sic,
            "lcp_compute_error": err_sic,
            "solved": bool(info == 0 and err_sic <= tol),
        },
        "ours_checked_by_siconos": {"residual_inf": res_ours, "lcp_compute_error": err_ours},
        "max_z_difference_rel": float(np.max(np.abs(z - zo))) / zscale,
        "siconos_version": getattr(__import__("siconos"), "__version__", "4.4 (Debian python3-siconos)"),
    }
    with open(out_path, "w") as f:
        json.dump(out, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
