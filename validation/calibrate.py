"""Measure the error constants behind the tolerance formulas (harness/compare.py).

For every case and every marchable scheme, march the engine's discrete equations (the discrete
marchers reproduce the engine's periodic solutions, see marching/multistep.py) at k = 128 ... 1024
and compare with the continuous reference of the case. Prints err / (ω_max h)^p, the constant C of
tol = C (ω_max h)^p. Not part of the test run (about a minute):

    .venv/bin/python calibrate.py
"""
from __future__ import annotations

import sys

import numpy as np

from harness.cases import CASES, continuous
from harness.compare import order, ref_on_grid
from marching.central_difference import march_cds
from marching.model import relative_errors
from marching.multistep import march_multistep
from marching.exact import linear_response

KS = (128, 256, 512, 1024)


def main(names):
    for name in names or CASES:
        case = CASES[name]
        sys_ = case.system
        ref = continuous(name)
        wmax = sys_.max_frequency()
        print(f"== {name}: ω = {sys_.omega}, ω_max = {wmax:.4f}, reference {ref.method}: {ref.periods} periods, "
              f"{ref.cpu_time:.2f} s, error bound {ref.error_bound:.1e}")
        schemes = sorted({(r.scheme, r.pairing) for r in case.runs if r.scheme != "fourier"})
        for scheme, pairing in schemes:
            p = order(case, scheme, pairing)
            for k in KS:
                h = sys_.period / k
                try:
                    if scheme == "cds":
                        d = march_cds(sys_, k, pairing=pairing, tol=1e-11)
                    else:
                        d = march_multistep(sys_, scheme, k, pairing=pairing, tol=1e-11)
                except Exception as e:  # noqa: BLE001
                    print(f"  {scheme}/{pairing} k={k}: {e}")
                    continue
                x_ref, v_ref = ref_on_grid(ref, d.t)
                ex, _ = relative_errors(x_ref, d.x)
                ev, _ = relative_errors(v_ref, d.v)
                imp = np.max(np.abs(d.impulse - ref.impulse) / np.maximum(np.abs(ref.impulse), 1e-300)) if sys_.m else 0.0
                s = (wmax * h) ** p
                print(f"  {scheme}/{pairing} p={p} k={k:5d}: x {ex:.3e} (C={ex / s:.3f})  v {ev:.3e} (C={ev / s:.3f})"
                      f"  impulse {imp:.3e} (C={imp / s:.3f})  periods {d.periods}")


if __name__ == "__main__":
    main(sys.argv[1:])
