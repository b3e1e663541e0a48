"""Random family for the event-fitted half-step law (prototype): errors at k = 256/512/1024 against the
event-driven exact orbit, the order, and the Richardson (order 2) estimate's ratio to the true error.
Usage: python friction_event_fitted_family.py [seed] [draws] [kinds, comma-separated, cycled]"""
import sys
import numpy as np
from friction_event_fitted import system, solve
import friction_exact as fe

seed = int(sys.argv[1]) if len(sys.argv) > 1 else 7
draws = int(sys.argv[2]) if len(sys.argv) > 2 else 8
kinds = (sys.argv[3] if len(sys.argv) > 3 else "den_hartog_c0,den_hartog_damped,chain,jenkins").split(",")
rng = np.random.default_rng(seed)
rows = []
for i in range(draws):
    kind = kinds[i % len(kinds)]
    c = 0.0 if kind == "den_hartog_c0" else rng.uniform(0.02, 0.2)
    om = rng.uniform(0.4, 2.0) if kind != "chain" else rng.uniform(0.3, 1.6)
    sl = rng.uniform(0.1, 0.9)
    kt = rng.uniform(1.0, 5.0) if kind == "jenkins" else None
    s = system(c, om, sl, kt=kt, chain=kind == "chain")
    try:
        orb = fe.solve(s, substeps=2000, march_tol=1e-11, max_periods=20000)
    except Exception as e:  # noqa: BLE001
        print(kind, c, om, sl, "exact failed", e)
        continue
    A = orb.amplitude()[s.dof]
    stuck = orb.stuck_fraction()
    res = {}
    for k in (256, 512, 1024):
        us, fs, vs, rounds = solve(s, k, True)
        t = np.arange(k) * s.period / k
        x = orb.displacement(t)
        res[k] = (us, np.abs(us - x).max() / A, rounds)
    e = [res[k][1] for k in (256, 512, 1024)]
    order = np.log2(e[1] / e[2])
    # Richardson order 2 at k = 512 from 256: on the coarse instants.
    est = np.abs(res[512][0][::2] - res[256][0]).max() / 3 / A
    true512 = e[1]
    print(f"{kind:18s} c={c:.3f} Ω={om:.3f} μN={sl:.3f} stuck={stuck:.3f}: err {e[0]:.2e} {e[1]:.2e} {e[2]:.2e} order(512→1024) {order:.2f}"
          f" est512/true {est / true512:.2f} rounds {[res[k][2] for k in (256, 512, 1024)]}", flush=True)
