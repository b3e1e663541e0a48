"""The FMU (`periodic-contact fmu SCENE.toml -o NAME.fmu`, FMI 2 CS) through fmpy.simulate_fmu
against the time-marching references.

Per case (its `fmu_run`: scheme, pairing, k):
  - test_fmu_model_description: fmpy validation passes; modelIdentifier, the contract's parameters
    (causality/variability) and outputs exist;
  - test_fmu_vs_marching: 3 periods with the communication step T/k: the outputs are T-periodic,
    agree with the CLI result of the same scene (1e-9), with the discrete marcher (1e-6), with
    the continuous marcher within C (ω_max h)^p, impulse per period and first-impact phase as for
    the CLI;
  - test_fmu_parameters: force_scale, frequency (linear case, exact discrete formula) and
    gap_offset (compliant case, discrete marcher) applied through start values change the
    response as they should;
  - test_fmu_libcosim_matches_fmpy: a second importer (libcosimpy, FMI Library) gives the same
    outputs;
  - test_fmu_communication_step_not_on_grid: outputs at communication times off the sample grid
    stay within the scheme tolerance plus one sample interval of motion (interpolation between
    samples is not specified by the contract, sample-and-hold is accepted).
Skipped while the CLI is absent (PC_REQUIRE_BINARIES=1: failed instead).
"""
import numpy as np
import pytest

from harness import checks, compare, engine, store
from harness.cases import CASES, continuous, discrete
from harness.report import REPORT, Row
from harness.scene import scene_toml
from marching.central_difference import march_cds
from marching.exact import linear_discrete, linear_response

pytestmark = pytest.mark.engine

PERIODS = 3
# FMU vs CLI on the same scene: the same engine and solve, only transport differs.
SAME_ENGINE = 1e-9


@pytest.fixture(scope="module")
def fmus(cli, workdir):
    cache = {}

    def get(name):
        if name not in cache:
            case = CASES[name]
            run = case.fmu_run
            text = scene_toml(case.system, run.scheme, run.steps, run.pairing,
                              comment=f"{case.title}\nvalidation case {name}, FMU run {run.label}")
            cache[name] = engine.build_fmu(cli, text, workdir, f"fmu_{name}")
        return cache[name]

    return get


def _cli_result(cli, workdir, name):
    case = CASES[name]
    run = case.fmu_run
    key = (name, run.label)
    if key not in store.ENGINE:
        text = scene_toml(case.system, run.scheme, run.steps, run.pairing)
        store.ENGINE[key] = engine.solve(cli, text, workdir, f"{name}_{run.scheme}_{run.pairing}_{run.steps}")
    return store.ENGINE[key]


@pytest.mark.parametrize("name", list(CASES))
def test_fmu_model_description(fmus, name):
    from fmpy.validation import validate_fmu

    case = CASES[name]
    fmu = fmus(name)
    problems = validate_fmu(fmu)
    problems += engine.check_fmu_contract(fmu, case.output_dofs, case.system.m)
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("name", list(CASES))
def test_fmu_vs_marching(cli, workdir, fmus, name):
    case = CASES[name]
    run = case.fmu_run
    s = case.system
    T, k = s.period, run.steps
    fr = engine.simulate_fmpy(fmus(name), case.output_dofs, s.m, T, PERIODS, k)
    store.FMU[name] = fr
    fails = []
    n_expected = PERIODS * k + 1
    if fr.time.size != n_expected:
        fails.append(f"{fr.time.size} output points, expected {n_expected}")
    dofs = case.output_dofs
    X = np.array([fr.values[f"x{d}"] for d in dofs])
    V = np.array([fr.values[f"v{d}"] for d in dofs])
    F = np.array([fr.values[f"f{i}"] for i in range(s.m)]) if s.m else np.zeros((0, X.shape[1]))
    amp = max(float(np.max(np.ptp(X, axis=1))), 1e-300)

    # T-periodic output
    per = np.max(np.abs(X[:, k:] - X[:, :-k])) / amp if X.shape[1] > k else np.inf
    if per > 1e-9:
        fails.append(f"outputs not T-periodic: max |x(t+T) - x(t)| / ptp = {per:.3e}")

    # first period, samples j = 0..k-1
    t1, X1, V1, F1 = fr.time[:k], X[:, :k], V[:, :k], F[:, :k]
    impulse = (T / k) * F1.sum(axis=1)

    # same engine through the CLI
    res = _cli_result(cli, workdir, name)
    d_cli = np.max(np.abs(X1 - res.X(dofs))) / amp
    if d_cli > SAME_ENGINE:
        fails.append(f"FMU differs from the CLI result of the same scene by {d_cli:.3e} > {SAME_ENGINE:g}")
    if s.m:
        d_f = np.max(np.abs(F1 - res.force)) / max(float(np.max(np.abs(res.force))), 1e-300)
        if d_f > SAME_ENGINE:
            fails.append(f"FMU contact force differs from the CLI's by {d_f:.3e}")

    ref = continuous(name)
    c = checks.vs_continuous(case, run, ref, t1, X1, V1)
    io = checks.impulse_and_onset(case, run, ref, t1, F1, impulse, T)
    fails += c["fails"] + io["fails"]
    disc = discrete(name, run.scheme, run.pairing, k)
    if disc is not None:
        dd = checks.vs_discrete(case, run, disc, X1, V1, F1)
        fails += dd["fails"]
    if "pivots" in fr.values and np.any(fr.values["pivots"] < 0):
        fails.append("lcp.pivots < 0")
    if "residual" in fr.values and not np.all(fr.values["residual"] <= 1e-8):
        fails.append(f"lcp.residual up to {np.max(fr.values['residual']):.3e}")
    imp = ", ".join(f"{v:.5f}" for v in impulse)
    REPORT.add(Row(name, f"FMU (fmpy) {run.label}, {PERIODS} periods vs {ref.method}", c["x_max"], c["x_rms"],
                   c["tol_x"], imp if s.m else "",
                   ", ".join("-" if p is None else f"{p:.4f}" for p in io["onsets"]),
                   f"fmpy wall {fr.wall_s:.2f} s; marching {ref.periods} periods, {ref.cpu_time:.2f} s CPU",
                   "pass" if not fails else "FAIL"))
    assert not fails, "\n".join(fails)


def test_fmu_parameters(fmus):
    """Tunable parameters through start values: force_scale and frequency on the linear case
    (against the exact discrete formula of the modified system, 1e-9), gap_offset on the
    compliant case (against the discrete cds marcher with the shifted gap, 1e-6)."""
    fails = []
    case = CASES["linear_2dof"]
    run = case.fmu_run
    fmu = fmus(case.name)
    for sv in ({"force_scale": 2.0}, {"frequency": 0.9}, {"force_scale": 0.5, "frequency": 0.7}):
        s2 = case.system.with_parameters(frequency=sv.get("frequency"), force_scale=sv.get("force_scale", 1.0))
        fr = engine.simulate_fmpy(fmu, case.output_dofs, 0, s2.period, 1, run.steps, start_values=sv)
        x, _, _ = linear_discrete(s2, run.scheme, run.steps)
        X = np.array([fr.values[f"x{d}"] for d in case.output_dofs])[:, :run.steps]
        err = np.max(np.abs(X - x)) / np.max(np.ptp(x, axis=1))
        if err > checks.LINEAR_DISCRETE_TOL:
            fails.append(f"linear_2dof with {sv}: error {err:.3e} against the exact discrete formula")
    case = CASES["compliant_1dof"]
    run = case.fmu_run
    s2 = case.system.with_parameters(gap_offset=0.2)
    fr = engine.simulate_fmpy(fmus(case.name), case.output_dofs, 1, s2.period, 1, run.steps,
                              start_values={"gap_offset": 0.2})
    d = march_cds(s2, run.steps, pairing=run.pairing, tol=1e-11)
    X = np.array([fr.values["x0"]])[:, :run.steps]
    err = np.max(np.abs(X - d.x)) / np.ptp(d.x)
    if err > checks.TIGHT:
        fails.append(f"compliant_1dof with gap_offset 0.2: error {err:.3e} against the discrete marcher")
    assert not fails, "\n".join(fails)


def test_fmu_libcosim_matches_fmpy(fmus):
    """Second importer: libcosimpy (FMIL loader, stepping on a worker thread) gives the fmpy
    outputs. Its time is integer nanoseconds (step T/k rounded to 1 ns, up to k/2 ns drift over
    a period), hence 1e-5 of the amplitude rather than round-off."""
    case = CASES["rigid_stick_1dof"]
    run = case.fmu_run
    s = case.system
    fmu = fmus(case.name)
    lc = engine.simulate_libcosim(fmu, case.output_dofs, s.m, s.period, 1, run.steps)
    fp = engine.simulate_fmpy(fmu, case.output_dofs, s.m, s.period, 1, run.steps)
    assert lc.time.size > run.steps // 2, f"libcosim returned {lc.time.size} samples"
    j = np.rint(lc.time / (s.period / run.steps)).astype(int)
    sel = (j >= 0) & (j < fp.time.size)
    amp = np.ptp(fp.values["x0"])
    err = np.max(np.abs(lc.values["x0"][sel] - fp.values["x0"][j[sel]])) / amp
    assert err < 1e-5, err


def test_fmu_communication_step_not_on_grid(fmus):
    """Linear case, communication step T/100 with k = 256 samples per period: within the scheme's
    tolerance plus h max|v| / ptp(x) of the continuous solution (sample-and-hold bound; linear
    interpolation would do better). A wrong phase origin (time 0 != phase 0) fails this by O(1)."""
    case = CASES["linear_2dof"]
    run = case.fmu_run
    s = case.system
    fr = engine.simulate_fmpy(fmus(case.name), case.output_dofs, 0, s.period, 2, 100)
    x, v, _ = linear_response(s, fr.time)
    X = np.array([fr.values[f"x{d}"] for d in case.output_dofs])
    h = s.period / run.steps
    ptp = np.ptp(x, axis=1)
    bound = compare.tolerance(case, run.scheme, run.pairing, run.steps) + np.max(h * np.max(np.abs(v), axis=1) / ptp)
    err = np.max(np.abs(X - x) / ptp[:, None])
    assert err <= bound, (err, bound)


def test_fmu_polish_exact_between_samples(cli, workdir):
    """The shipped fmu/scenes/rigid-stop.toml (cds, k = 256) with the parameter polish = true set
    through fmpy's start values: at communication points between the samples (step 1.37 T/k over
    two periods) displacement, velocity, contact force and gap are the exact orbit's
    (marching/exact.py, rigid stop with sticking, src/formulation.md §6.3) within 1e-8 of the peak-to-peak
    amplitude, and polish.status = 1. Without the polish the same outputs are the interpolated
    samples, off by far more (the LCP's own error), which shows the check can fail."""
    import os

    from fmpy import simulate_fmu
    from marching.exact import rigid_stop_sticking

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(root, "fmu", "scenes", "rigid-stop.toml")) as fh:
        fmu = engine.build_fmu(cli, fh.read(), workdir, "fmu_rigid_stop_polish")
    orbit = rigid_stop_sticking(1.0, 0.1, 1.0, 1.0, 0.5, 1.0)
    T = orbit.T
    names = ["displacement[0]", "velocity[0]", "contact[0].force", "contact[0].gap", "polish.status"]
    errs = {}
    for polish in (True, False):
        res = simulate_fmu(fmu, fmi_type="CoSimulation", start_time=0.0, stop_time=2 * T,
                           output_interval=1.37 * T / 256, start_values={"polish": polish}, output=names)
        t = np.asarray(res["time"], dtype=float)
        assert np.all(np.asarray(res["polish.status"]) == (1 if polish else 0)), res["polish.status"]
        x, v = orbit.state(t)
        want = {"displacement[0]": x, "velocity[0]": v, "contact[0].force": orbit.force(t), "contact[0].gap": 0.5 - x}
        ptp = np.ptp(x)
        errs[polish] = max(float(np.max(np.abs(np.asarray(res[n], dtype=float) - w))) / ptp for n, w in want.items())
    assert errs[True] <= 1e-8, f"polished FMU outputs off the exact orbit by {errs[True]:.3e} of ptp"
    assert errs[False] > 1e3 * errs[True], errs
