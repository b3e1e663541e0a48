"""A probe of pyharm-os (PyPI, SAFRAN's pyHarm) on the Jenkins damper of
fmu/scenes/friction-damper.toml: m = k = 1, c = 0.1, P cos Ωt with P = 1, a Jenkins element
k_t = 2, μN = 0.5. Modelled as pyHarm connectors: a massless "slider" substructure tied to the
mass by a LinearSpring k_t and to the ground by a DLFTFriction (mu = 0.25, N0 = 2). One frequency,
pyHarm's "nocontinuation" corrector. Not part of the test suite: pyharm-os pulls ~100 packages
(jax, numba, jupyterlab), so it lives in its own venv:

    python3 -m venv /tmp/pyharm-venv && /tmp/pyharm-venv/bin/pip install pyharm-os
    /tmp/pyharm-venv/bin/python validation/peers/friction_pyharm_probe.py OMEGA NH EPS

Prints the first accepted solutions (Ω, amplitude of the mass) and the CPU time.
"""
import sys
import time

import numpy as np
from pyHarm.DynamicOperator import compute_DFT
from pyHarm.Maestro import Maestro

omega, nh, eps = float(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])


def zero():
    return np.zeros((1, 1))   # a fresh array each: pyHarm may write into its inputs


DATA = {
    "analysis": {"a": {"study": "frf", "puls_inf": omega, "puls_sup": omega * 1.0001, "puls_start": omega,
                       "ds0": 1e-5, "ds_min": 1e-9, "ds_max": 1e-4, "sign_ds": 1, "verbose": False,
                       "corrector": "nocontinuation", "stopper": "bounds"}},
    "system": {"type": "Base", "nh": nh, "nti": 1024, "adim": {"status": False, "lc": 1.0, "wc": 1.0}},
    "substructures": {
        "mass": {"matrix": {"M": np.eye(1), "C": 0.1 * np.eye(1), "K": np.eye(1), "G": zero()}, "ndofs": 1},
        "slider": {"matrix": {"M": zero(), "C": zero(), "K": zero(), "G": zero()}, "ndofs": 1},
    },
    "connectors": {
        "loading": {"type": "CosinusForcing", "connect": {"mass": [0]}, "dirs": [0], "amp": 1.0},
        "kt": {"type": "LinearSpring", "connect": {"mass": [0], "slider": [0]}, "dirs": [0], "k": 2.0},
        "fric": {"type": "DLFTFriction", "connect": {"slider": [0]}, "dirs": [0], "mu": 0.25, "N0": 2.0, "eps": eps},
    },
}
t = time.process_time()
m = Maestro(DATA)
ix = m.getIndex("mass", 0, 0)
m.operate()
dft = compute_DFT(m.system.nti, m.system.nh)
for s in [s for s in m.nls["a"].SolList if s.flag_accepted][:2]:
    x = s.x[ix] @ dft["ft"]
    print(f"Ω {s.x[-1]:.7f}: amplitude {0.5 * (x.max() - x.min()):.10f}")
print(f"cpu {time.process_time() - t:.2f} s")
