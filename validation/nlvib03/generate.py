"""Regenerate validation/nlvib03/reference.json and nlvib03.png (NLvib Example 03 reference).

    validation/.venv/bin/python validation/nlvib03/generate.py     # ~3 min on 2 cores

1. T-periodic branch: shooting at Ω = 0.5 from rest, pseudo-arclength continuation to Ω = 0.8
   with events (branch.py).
2. 2T branches: branch switching at each period doubling, continued until they rejoin the
   T-branch (or leave [0.5, 0.8]).
3. Long time integration (marching.py, exact flow) at a grid of Ω from rest and from four large
   initial conditions; each run's end state is matched with the branches' orbits at that Ω.
   Checks: every stable orbit is reached by some run, no run ends on an unstable orbit, and the
   runs that stay non-periodic lie where no stable T- or 2T-orbit exists.
"""
from __future__ import annotations

import json
import os
import sys
import time
from multiprocessing import Pool

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
if os.path.dirname(HERE) not in sys.path:
    sys.path.insert(0, os.path.dirname(HERE))

from nlvib03.branch import (Branch, ShootingFailed, continuation, make_orbit, period_doubling_start,  # noqa: E402
                            rejoin_stop, shoot)
from nlvib03.flow import Nlvib03  # noqa: E402
from nlvib03.marching import march  # noqa: E402

OMEGA_RANGE = (0.5, 0.8)
INITIAL_CONDITIONS = {            # y(0) = [x0, x1, v0, v1]
    "rest": [0.0, 0.0, 0.0, 0.0],
    "large_1": [3.0, 2.0, 0.0, 0.0],
    "large_2": [-3.0, -2.0, 0.0, 0.0],
    "large_3": [0.0, 0.0, 2.0, 2.0],
    "large_4": [2.0, -1.0, -2.0, 1.0],
}
# the coarse grid over the range, and more points inside the quasi-periodic window and the
# period-doubling region (none within 1e-3 of an event: convergence there takes too long)
MARCH_OMEGAS = sorted(set(np.round(np.arange(0.50, 0.8001, 0.01), 4).tolist()
                          + [0.5825, 0.585, 0.595, 0.605, 0.615, 0.6175, 0.625, 0.6775, 0.735, 0.745, 0.7545]))
MARCH_MAX_PERIODS = 3000
MARCH_TOL = 1e-10                  # ‖y_n - y_{n-p}‖∞ at which a run counts as pT-periodic
MATCH_TOL = 1e-6                   # state and amplitude distance of a reached orbit


def log(msg: str):
    print(msg, flush=True)


def orbit_record(o, label: str) -> dict:
    return {
        "omega": o.omega,
        "amplitude_0": float(o.measures["amplitude_0"]),
        "amplitude_1": float(o.measures["amplitude_1"]),
        "max_x0": float(o.measures["max_x0"]),
        "switches": int(o.measures["switches"]),
        "max_multiplier": o.max_multiplier,
        "stable": bool(o.stable),
        "period_multiple": o.period_multiple,
        "multipliers": [[float(m.real), float(m.imag)] for m in o.multipliers],
        "state": [float(v) for v in o.s],
        "branch": label,
    }


def branches() -> list[tuple[str, Branch]]:
    o0 = shoot(np.zeros(4), OMEGA_RANGE[0])
    main = continuation(o0, +1.0, OMEGA_RANGE, log=log)
    out = [("T", main)]
    pds = [e.orbit for e in main.events if e.kind == "period_doubling"]
    done = []
    for pd in pds:
        if any(abs(pd.omega - o.omega) < 1e-9 for o in done):
            continue           # reached as the end of an earlier 2T branch
        o2, t = period_doubling_start(pd)
        b2 = continuation(o2, +1.0, OMEGA_RANGE, p=2, start_tangent=t, ds0=1e-3, log=log,
                          stop=rejoin_stop(pds))
        done.append(pd)
        done.append(b2.orbits[-1])
        out.append((f"2T from Ω = {pd.omega:.4f}", b2))
    return out


def orbits_at(omega: float, br: Branch) -> list:
    """All orbits of branch br at Ω (fixed-Ω shooting from the interpolated branch states)."""
    found = []
    obs = br.orbits
    for a, b in zip(obs[:-1], obs[1:]):
        if (a.omega - omega) * (b.omega - omega) <= 0 and a.omega != b.omega:
            w = (omega - a.omega) / (b.omega - a.omega)
            try:
                o = shoot(a.s + w * (b.s - a.s), omega, br.period_multiple)
            except ShootingFailed:
                continue
            if not any(np.max(np.abs(o.s - f.s)) < 1e-7 for f in found):
                found.append(o)
    return found


def _march_job(args):
    omega, name = args
    r = march(omega, INITIAL_CONDITIONS[name], MARCH_MAX_PERIODS, MARCH_TOL)
    return omega, name, r


def _shifted_states(o) -> list[np.ndarray]:
    """A pT-orbit's states at t = 0, T, …: time integration may land on any of the p shifts."""
    sysm = Nlvib03(o.omega)
    states, y = [o.s], o.s
    for _ in range(o.period_multiple - 1):
        y = sysm.integrate(0.0, y, sysm.T).y
        states.append(y)
    return states


def _other_attractor(om: float, r, others: list):
    """Shoot a pT-orbit from a periodic run's end state; record it (once) in `others`."""
    p = r.period_multiple
    try:
        o = shoot(r.y, om, p)
    except ShootingFailed:
        return None
    d = float(np.max(np.abs(o.s - r.y)))
    for rec in others:
        if rec["omega"] == om and rec["period_multiple"] == p and min(
                float(np.max(np.abs(np.array(rec["state"]) - st))) for st in _shifted_states(o)) < MATCH_TOL:
            return dict(rec, distance_to_run=d)
    rec = orbit_record(o, f"{p}T (time integration + shooting)")
    rec["distance_to_run"] = d
    if d < MATCH_TOL:
        others.append(rec)
        return rec
    return None


def time_integration(brs) -> tuple[list, dict]:
    jobs = [(om, name) for om in MARCH_OMEGAS for name in INITIAL_CONDITIONS]
    with Pool(min(2, os.cpu_count() or 1)) as pool:
        results = pool.map(_march_job, jobs, chunksize=1)
    runs, checks = [], {"stable_reached": [], "unstable_approached": [], "nonperiodic": [], "unmatched": [],
                        "other_attractors": [], "window": []}
    for om in MARCH_OMEGAS:
        orbs = [(lab, o) for lab, br in brs for o in orbits_at(om, br)]
        rs = [(name, r) for (w, name, r) in results if w == om]
        matched_by = {i: [] for i in range(len(orbs))}
        for name, r in rs:
            rec = {"omega": om, "initial": name, "kind": r.kind, "periods": r.periods, "defect": r.defect,
                   "amplitude_0": r.amplitude_0, "amplitude_1": r.amplitude_1, "strobe_spread": r.strobe_spread,
                   "matched_branch": None, "state_distance": None, "amplitude_distance": None}
            best = (np.inf, None)
            for i, (lab, o) in enumerate(orbs):
                d = min(float(np.max(np.abs(r.y - st))) for st in _shifted_states(o))
                if d < best[0]:
                    best = (d, i)
            if best[1] is not None:
                lab, o = orbs[best[1]]
                rec["state_distance"] = best[0]
                rec["amplitude_distance"] = abs(r.amplitude_0 - o.measures["amplitude_0"])
                if r.kind != "nonperiodic" and best[0] < MATCH_TOL:
                    rec["matched_branch"] = lab
                    rec["matched_stable"] = bool(o.stable)
                    matched_by[best[1]].append(name)
                    if not o.stable:
                        checks["unstable_approached"].append(rec)
            if r.kind == "nonperiodic":
                checks["nonperiodic"].append(om)
            elif rec["matched_branch"] is None:
                # a periodic attractor off the T and 2T branches: confirm it by shooting over pT
                other = _other_attractor(om, r, checks["other_attractors"])
                if other is None:
                    checks["unmatched"].append(rec)
                else:
                    rec["matched_branch"] = other["branch"]
                    rec["matched_stable"] = other["stable"]
                    rec["state_distance"] = other["distance_to_run"]
            runs.append(rec)
        has_stable = any(o.stable for _, o in orbs)
        checks["window"].append({"omega": om, "stable_T_or_2T_orbit": has_stable,
                                 "runs_nonperiodic": sum(r.kind == "nonperiodic" for _, r in rs),
                                 "runs": len(rs)})
        for i, (lab, o) in enumerate(orbs):
            if not o.stable:
                continue
            entry = {"omega": om, "branch": lab, "amplitude_0": float(o.measures["amplitude_0"]),
                     "reached_by": matched_by[i]}
            if not matched_by[i]:
                # not in the basin of our five starts: start 1e-2 off the orbit instead
                r = march(om, o.s + 1e-2, MARCH_MAX_PERIODS, MARCH_TOL)
                d = min(float(np.max(np.abs(r.y - st))) for st in _shifted_states(o))
                entry["reached_from_perturbation"] = bool(d < MATCH_TOL)
            checks["stable_reached"].append(entry)
        log(f"  Ω = {om:.4f}: orbits " + ", ".join(f"{lab}:{o.measures['amplitude_0']:.4f}{'s' if o.stable else 'u'}"
                                                    for lab, o in orbs)
            + " | runs " + ", ".join(f"{r.kind}:{r.amplitude_0:.4f}" for _, r in rs))
    checks["nonperiodic"] = sorted(set(checks["nonperiodic"]))
    # non-periodic runs only where no stable T- or 2T-orbit exists; where none exists, every run is
    # non-periodic or ends on a confirmed pT-orbit off the branches (p >= 3: phase locking)
    other_at = {o["omega"] for o in checks["other_attractors"]}
    checks["window_inconsistent"] = [
        w for w in checks["window"]
        if (w["stable_T_or_2T_orbit"] and w["runs_nonperiodic"] > 0)
        or (not w["stable_T_or_2T_orbit"] and w["runs_nonperiodic"] < w["runs"] and w["omega"] not in other_at)]
    return runs, checks


def plot(brs, events, runs, others, path: str):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(9, 10), sharex=True)
    colors = {"T": "tab:blue"}
    for k, ax in enumerate(axes):
        for lab, br in brs:
            c = colors.get(lab, "tab:orange")
            om = np.array([o.omega for o in br.orbits])
            a = np.array([o.measures[f"amplitude_{k}"] for o in br.orbits])
            st = np.array([o.stable for o in br.orbits])
            first = True
            # draw runs of equal stability; unstable dashed
            start = 0
            for i in range(1, len(om) + 1):
                if i == len(om) or st[i] != st[start]:
                    seg = slice(start, min(i + 1, len(om)))
                    ax.plot(om[seg], a[seg], "-" if st[start] else "--", color=c, lw=1.6,
                            label=(f"{lab}-periodic orbits" if lab == "T" else "2T-periodic orbits") if first else None)
                    first = False
                    start = i
        per = [r for r in runs if r.get("matched_branch")]
        ax.plot([r["omega"] for r in per], [r[f"amplitude_{k}"] for r in per], "o", mfc="none", mec="k", ms=6,
                label="time integration: periodic end state")
        qp = [r for r in runs if r["kind"] == "nonperiodic"]
        ax.plot([r["omega"] for r in qp], [r[f"amplitude_{k}"] for r in qp], "x", color="tab:red", ms=7,
                label="time integration: non-periodic (last 4 periods)")
        if others:
            ax.plot([o["omega"] for o in others], [o[f"amplitude_{k}"] for o in others], "^", color="tab:olive", ms=8,
                    label="4T orbit (time integration, confirmed by 4T shooting)")
        marks = {"fold": ("s", "tab:green"), "grazing": ("v", "tab:purple"), "period_doubling": ("D", "tab:red"),
                 "neimark_sacker": ("*", "tab:brown"), "branch_point": ("P", "k")}
        seen = set()
        for e in events:
            m, c = marks[e["type"]]
            ax.plot(e["omega"], e[f"amplitude_{k}"], m, color=c, ms=9,
                    label=e["type"].replace("_", " ") if e["type"] not in seen else None)
            seen.add(e["type"])
        ax.set_ylabel(f"amplitude of DOF {k} (half peak-to-peak) [m]")
        ax.grid(alpha=0.3)
    axes[0].axhline(1.0, color="grey", lw=0.8, ls=":")
    axes[0].text(0.505, 1.02, "gap = 1 m", color="grey")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=3)
    axes[1].set_xlabel("excitation frequency Ω [rad/s]")
    axes[0].set_title("NLvib Example 03 (unilateral spring k = 100, gap 1): exact shooting + continuation\n"
                      "solid stable, dashed unstable; markers: events and long time integration")
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    t0 = time.time()
    brs = branches()
    t_cont = time.time() - t0
    events = []
    for lab, br in brs:
        for e in br.events:
            rec = orbit_record(e.orbit, lab)
            rec["type"] = e.kind
            rec["detail"] = e.detail
            events.append(rec)
    events.sort(key=lambda e: e["omega"])
    log("time integration …")
    runs, checks = time_integration(brs)
    # the physical resonance peak: the largest x0 amplitude over the stable orbits of all branches
    stable = [(lab, o) for lab, br in brs for o in br.orbits if o.stable]
    lab_pk, pk = max(stable, key=lambda x: x[1].measures["amplitude_0"])
    _, spk = max(((lab, o) for lab, br in brs if br.period_multiple == 1 for o in br.orbits if o.stable),
                 key=lambda x: x[1].measures["amplitude_0"])
    lab_tpk, tpk = max(((lab, o) for lab, br in brs if br.period_multiple == 1 for o in br.orbits),
                       key=lambda x: x[1].measures["amplitude_0"])
    ns = sorted(e["omega"] for e in events if e["type"] == "neimark_sacker")
    ref = {
        "system": {
            "description": "NLvib Example 03 (Krack & Gross 2019): x'' + D x' + K x + e0*kc*max(0, x0 - gap) = e1*f*cos(Ω t)",
            "M": [[1, 0], [0, 1]], "K": [[1, -1], [-1, 2]], "D": "0.03*K", "contact_dof": 0, "contact_stiffness": 100.0,
            "gap": 1.0, "force_dof": 1, "force_amplitude": 0.1, "omega_range": list(OMEGA_RANGE),
            "units": {"omega": "rad/s", "amplitude": "m (half peak-to-peak)"},
            "state": "state = y(0) = [x0, x1, v0, v1] at t = 0 (forcing phase cos(Ω t))",
        },
        "method": "exact piecewise-linear flows (switches by Brent on the exact flow), shooting with the exact "
                  "monodromy (identity saltation), pseudo-arclength continuation with located events; "
                  "long time integration from 5 initial conditions; see validation/nlvib03/README.md",
        "generator": "validation/.venv/bin/python validation/nlvib03/generate.py",
        "runtime_s": {"continuation": round(t_cont, 1)},
        "branches": [{"label": lab, "period_multiple": br.period_multiple,
                      "points": [orbit_record(o, lab) for o in br.orbits]} for lab, br in brs],
        "events": events,
        "resonance_peak": {
            "stable": {"branch": lab_pk, "omega": pk.omega, "amplitude_0": float(pk.measures["amplitude_0"]),
                       "amplitude_1": float(pk.measures["amplitude_1"])},
            "stable_T": {"omega": spk.omega, "amplitude_0": float(spk.measures["amplitude_0"]),
                         "amplitude_1": float(spk.measures["amplitude_1"])},
            "T_branch": {"omega": tpk.omega, "amplitude_0": float(tpk.measures["amplitude_0"]),
                         "amplitude_1": float(tpk.measures["amplitude_1"]), "stable": bool(tpk.stable)},
        },
        "quasi_periodic_window": {"omega_from": ns[0] if ns else None, "omega_to": ns[-1] if ns else None,
                                  "nonperiodic_runs_at": checks["nonperiodic"]},
        "time_integration": {"initial_conditions": INITIAL_CONDITIONS, "max_periods": MARCH_MAX_PERIODS,
                             "periodicity_tol": MARCH_TOL, "match_tol": MATCH_TOL, "runs": runs},
        "checks": checks,
    }
    ref["runtime_s"]["total"] = round(time.time() - t0, 1)
    with open(os.path.join(HERE, "reference.json"), "w") as f:
        json.dump(ref, f, indent=1)
    plot(brs, events, runs, checks["other_attractors"], os.path.join(HERE, "nlvib03.png"))
    log("events:")
    for e in events:
        log(f"  {e['type']:16s} Ω = {e['omega']:.10f}  A0 = {e['amplitude_0']:.6f}  A1 = {e['amplitude_1']:.6f}"
            f"  [{e['branch']}] {e['detail']}")
    log(f"stable peak: {ref['resonance_peak']['stable']}")
    log(f"T-branch peak: {ref['resonance_peak']['T_branch']}")
    log(f"non-periodic runs at Ω = {checks['nonperiodic']}")
    bad = [e for e in checks["stable_reached"] if not e["reached_by"]]
    log(f"stable orbits not reached from the 5 starts: {bad}")
    log(f"runs ending on unstable orbits: {checks['unstable_approached']}")
    log(f"unmatched periodic runs: {checks['unmatched']}")
    for o in checks["other_attractors"]:
        log(f"other attractor: {o['branch']} at Ω = {o['omega']}: A0 = {o['amplitude_0']:.6f}, "
            f"max|μ| = {o['max_multiplier']:.4f}")
    log(f"Ω where the runs contradict the branches' stability: {checks['window_inconsistent']}")
    log(f"total {ref['runtime_s']['total']} s")


if __name__ == "__main__":
    main()
