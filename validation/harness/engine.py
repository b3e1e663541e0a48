"""Running the engine: the CLI (`periodic-contact solve` / `periodic-contact fmu`) and the FMU
(fmpy, libcosimpy), and reading their outputs against the contracts.

Contracts (fixed by the lead):
  solve SCENE.toml -o result.json   -> JSON with period, steps, scheme, pairing, effects, time,
      displacement/velocity/acceleration ({"<dof>": [k values]}), contacts [{dof, force, gap}],
      lcp {size, status, pivots, residual}, warnings, timing_s {assembly, lcp, recovery, total}.
      For rigid contacts `force` samples are impulses per step / h.
  fmu SCENE.toml -o NAME.fmu        -> FMI 2 CS, modelIdentifier PeriodicContact; parameters
      frequency, force_scale, gap_offset (tunable), steps, scheme (fixed); outputs displacement[d],
      velocity[d], contact[i].force, contact[i].gap, lcp.pivots, lcp.residual; the output at a
      communication time t is the periodic response at phase t (time 0 = phase 0).
"""
from __future__ import annotations

import ctypes
import json
import os
import subprocess
import time
from dataclasses import dataclass, field

import numpy as np

VALIDATION = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI_TIMEOUT_S = 300


def cli_path() -> str:
    p = os.environ.get("PC_CLI") or os.path.join(VALIDATION, "..", "target", "release", "periodic-contact")
    return os.path.abspath(p)


def cli_problem(path: str) -> str | None:
    if not os.path.exists(path):
        return f"not found at {path}"
    if not os.access(path, os.X_OK):
        return f"{path} is not executable"
    return None


class EngineError(RuntimeError):
    pass


def _run(cmd: list[str], what: str) -> tuple[subprocess.CompletedProcess, float]:
    t0 = time.perf_counter()
    try:
        cp = subprocess.run(cmd, capture_output=True, text=True, timeout=CLI_TIMEOUT_S)
    except subprocess.TimeoutExpired as e:
        raise EngineError(f"{what}: timed out after {CLI_TIMEOUT_S} s: {' '.join(cmd)}") from e
    wall = time.perf_counter() - t0
    if cp.returncode != 0:
        raise EngineError(f"{what} failed (exit {cp.returncode}): {' '.join(cmd)}\n"
                          f"stdout: {cp.stdout[-2000:]}\nstderr: {cp.stderr[-4000:]}")
    return cp, wall


# ----------------------------------------------------------------------------- CLI


@dataclass
class EngineResult:
    raw: dict
    path: str
    wall_s: float
    period: float
    steps: int
    t: np.ndarray
    x: dict[int, np.ndarray]
    v: dict[int, np.ndarray]
    a: dict[int, np.ndarray]
    force: np.ndarray          # (m, k)
    gap: np.ndarray            # (m, k)
    contact_dofs: list[int]
    lcp: dict
    warnings: list
    timing: dict
    problems: list[str] = field(default_factory=list)  # contract deviations found while parsing

    def X(self, dofs) -> np.ndarray:
        return np.array([self.x[d] for d in dofs])

    def V(self, dofs) -> np.ndarray:
        return np.array([self.v[d] for d in dofs])

    @property
    def impulse(self) -> np.ndarray:
        """h * Σ force per contact (rigid: impulses/h samples; compliant: quadrature)."""
        return (self.period / self.steps) * self.force.sum(axis=1) if self.force.size else np.zeros(0)

    @property
    def total_s(self) -> float | None:
        return self.timing.get("total") if isinstance(self.timing, dict) else None


REQUIRED_KEYS = ("period", "steps", "scheme", "pairing", "effects", "time", "displacement", "velocity",
                 "acceleration", "contacts", "lcp", "warnings", "timing_s")


def parse_result(raw: dict, path: str = "", wall_s: float = 0.0) -> EngineResult:
    problems = [f"missing key {k!r}" for k in REQUIRED_KEYS if k not in raw]
    k = int(raw.get("steps", len(raw.get("time", []))))
    t = np.asarray(raw.get("time", []), dtype=float)

    def dofmap(key):
        d = raw.get(key) or {}
        out = {}
        for s, vals in d.items():
            arr = np.asarray(vals, dtype=float)
            if arr.shape != (k,):
                problems.append(f"{key}[{s}] has shape {arr.shape}, expected ({k},)")
            out[int(s)] = arr
        return out

    contacts = raw.get("contacts") or []
    force = np.array([np.asarray(c.get("force", []), dtype=float) for c in contacts]) if contacts else np.zeros((0, k))
    gap = np.array([np.asarray(c.get("gap", []), dtype=float) for c in contacts]) if contacts else np.zeros((0, k))
    if t.shape != (k,):
        problems.append(f"time has shape {t.shape}, expected ({k},)")
    if contacts and (force.shape[1:] != (k,) or gap.shape[1:] != (k,)):
        problems.append(f"contact force/gap shapes {force.shape}/{gap.shape}, expected (m, {k})")
    lcp = raw.get("lcp") or {}
    for key in ("size", "status", "pivots", "residual"):
        if key not in lcp:
            problems.append(f"lcp.{key} missing")
    timing = raw.get("timing_s") or {}
    for key in ("assembly", "lcp", "recovery", "total"):
        if key not in timing:
            problems.append(f"timing_s.{key} missing")
    return EngineResult(raw=raw, path=path, wall_s=wall_s, period=float(raw.get("period", np.nan)), steps=k, t=t,
                        x=dofmap("displacement"), v=dofmap("velocity"), a=dofmap("acceleration"), force=force,
                        gap=gap, contact_dofs=[int(c.get("dof", -1)) for c in contacts], lcp=lcp,
                        warnings=list(raw.get("warnings") or []), timing=timing, problems=problems)


def solve(cli: str, scene_text: str, workdir: str, name: str, extra: tuple = ()) -> EngineResult:
    os.makedirs(workdir, exist_ok=True)
    scene = os.path.join(workdir, f"{name}.toml")
    out = os.path.join(workdir, f"{name}.json")
    with open(scene, "w") as fh:
        fh.write(scene_text)
    if os.path.exists(out):
        os.remove(out)
    _, wall = _run([cli, "solve", scene, "-o", out, *extra], f"periodic-contact solve {name}")
    with open(out) as fh:
        raw = json.load(fh)
    return parse_result(raw, out, wall)


def build_fmu(cli: str, scene_text: str, workdir: str, name: str) -> str:
    os.makedirs(workdir, exist_ok=True)
    scene = os.path.join(workdir, f"{name}.toml")
    fmu = os.path.join(workdir, f"{name}.fmu")
    with open(scene, "w") as fh:
        fh.write(scene_text)
    if os.path.exists(fmu):
        os.remove(fmu)
    _run([cli, "fmu", scene, "-o", fmu], f"periodic-contact fmu {name}")
    if not os.path.exists(fmu):
        raise EngineError(f"periodic-contact fmu {name}: exit 0 but {fmu} was not written")
    return fmu


def capi_displacements(cli: str, scene: str, keys, k: int, estimate: bool = True) -> dict[str, np.ndarray]:
    """The C API (libperiodic_contact.so beside the CLI) through ctypes, as a Python user calls it:
    pc_problem_from_scene_file, pc_problem_solve, pc_result_displacement of each key at the k instants.
    estimate=False: pc_problem_set_error_estimate(p, 0), as the CLI's --no-estimate (the C API's
    default estimates by a second solve at k/2, which is not the CLI's solve)."""
    c = ctypes
    lib = c.CDLL(os.path.join(os.path.dirname(cli), "libperiodic_contact.so"))
    lib.pc_last_error.restype = c.c_char_p
    lib.pc_problem_from_scene_file.restype = c.c_void_p
    lib.pc_problem_from_scene_file.argtypes = [c.c_char_p]
    lib.pc_problem_solve.restype = c.c_void_p
    lib.pc_problem_solve.argtypes = [c.c_void_p]
    lib.pc_result_steps.restype = c.c_size_t
    lib.pc_result_steps.argtypes = [c.c_void_p]
    lib.pc_result_displacement.argtypes = [c.c_void_p, c.c_size_t, c.POINTER(c.c_double), c.c_size_t]
    lib.pc_result_free.argtypes = [c.c_void_p]
    lib.pc_problem_free.argtypes = [c.c_void_p]
    p = lib.pc_problem_from_scene_file(scene.encode())
    if not p:
        raise EngineError(f"pc_problem_from_scene_file({scene}): {lib.pc_last_error().decode()}")
    try:
        if not estimate and lib.pc_problem_set_error_estimate(c.c_void_p(p), 0) != 0:
            raise EngineError(f"pc_problem_set_error_estimate({scene}): {lib.pc_last_error().decode()}")
        r = lib.pc_problem_solve(p)
        if not r:
            raise EngineError(f"pc_problem_solve({scene}): {lib.pc_last_error().decode()}")
        try:
            if lib.pc_result_steps(r) != k:
                raise EngineError(f"{scene}: the C API solved on {lib.pc_result_steps(r)} instants, the CLI on {k}")
            out = {}
            for key in keys:
                x = (c.c_double * k)()
                status = lib.pc_result_displacement(r, int(key), x, k)
                if status != 0:
                    raise EngineError(f"pc_result_displacement({key}): {lib.pc_last_error().decode()}")
                out[key] = np.frombuffer(x, dtype=float).copy()
            return out
        finally:
            lib.pc_result_free(r)
    finally:
        lib.pc_problem_free(p)


# ----------------------------------------------------------------------------- FMU


def fmu_output_names(output_dofs, m: int) -> dict[str, str]:
    """Contract names of the FMU outputs. DOF indices are the scene's (0-based), contact indices
    the position in the scene's [[contact]] list (0-based). Key: our label, value: FMI name."""
    names = {}
    for d in output_dofs:
        names[f"x{d}"] = f"displacement[{d}]"
        names[f"v{d}"] = f"velocity[{d}]"
    for i in range(m):
        names[f"f{i}"] = f"contact[{i}].force"
        names[f"g{i}"] = f"contact[{i}].gap"
    if m:
        # Without contacts there is no LCP, and no LCP variables.
        names["pivots"] = "lcp.pivots"
        names["residual"] = "lcp.residual"
    return names


PARAMETERS = ("frequency", "force_scale", "gap_offset", "steps", "scheme")


def fmu_variables(fmu: str) -> dict:
    from fmpy import read_model_description

    md = read_model_description(fmu)
    return {v.name: v for v in md.modelVariables}, md


def check_fmu_contract(fmu: str, output_dofs, m: int) -> list[str]:
    """Deviations of the FMU's model description from the contract (empty list: conforms)."""
    variables, md = fmu_variables(fmu)
    problems = []
    if md.fmiVersion != "2.0":
        problems.append(f"fmiVersion {md.fmiVersion}")
    if md.coSimulation is None:
        problems.append("no CoSimulation element")
    elif md.coSimulation.modelIdentifier != "PeriodicContact":
        problems.append(f"modelIdentifier {md.coSimulation.modelIdentifier!r}")
    for name in fmu_output_names(output_dofs, m).values():
        v = variables.get(name)
        if v is None:
            problems.append(f"output {name!r} missing")
        elif v.causality != "output":
            problems.append(f"{name!r} has causality {v.causality!r}")
    want = {"frequency": "tunable", "force_scale": "tunable", "gap_offset": "tunable", "steps": "fixed",
            "scheme": "fixed"}
    if m == 0:
        # Only the effects a scene calls for: without contacts there is no clearance to offset,
        # and no contact outputs.
        del want["gap_offset"]
        problems += [f"{n!r} present without contacts" for n in variables if n.startswith(("contact[", "gap_offset", "lcp."))]
    for name, var in want.items():
        v = variables.get(name)
        if v is None:
            problems.append(f"parameter {name!r} missing")
        else:
            if v.causality != "parameter":
                problems.append(f"{name!r} has causality {v.causality!r}")
            if v.variability != var:
                problems.append(f"{name!r} has variability {v.variability!r}, expected {var!r}")
    if problems:
        problems.append("variables present: " + ", ".join(sorted(variables)))
    return problems


@dataclass
class FmuRun:
    time: np.ndarray
    values: dict[str, np.ndarray]  # by our label (x0, v0, f0, g0, pivots, residual)
    wall_s: float


def simulate_fmpy(fmu: str, output_dofs, m: int, period: float, periods: int, steps_per_period: int,
                  start_values: dict | None = None) -> FmuRun:
    """fmpy.simulate_fmu over `periods` periods with the communication step T/steps_per_period."""
    from fmpy import simulate_fmu

    names = fmu_output_names(output_dofs, m)
    t0 = time.perf_counter()
    res = simulate_fmu(fmu, fmi_type="CoSimulation", start_time=0.0, stop_time=periods * period,
                       output_interval=period / steps_per_period, start_values=start_values or {},
                       output=list(names.values()))
    wall = time.perf_counter() - t0
    return FmuRun(time=np.asarray(res["time"], dtype=float),
                  values={lab: np.asarray(res[n], dtype=float) for lab, n in names.items()}, wall_s=wall)


def simulate_libcosim(fmu: str, output_dofs, m: int, period: float, periods: int, steps_per_period: int,
                      names: dict[str, str] | None = None) -> FmuRun:
    """The same run through libcosimpy (FMI Library loader, stepping on a worker thread). libcosim
    time is integer nanoseconds, so the step is rounded to 1 ns; outputs are returned at the
    communication points it reports (libcosimpy drops the step-0 sample). `names` (our label: FMI
    name) replaces the contract's outputs of `output_dofs` and `m`."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    names = names or fmu_output_names(output_dofs, m)
    step_ns = int(round(period / steps_per_period * 1e9))
    n_steps = periods * steps_per_period
    t0 = time.perf_counter()
    ex = CosimExecution.from_step_size(step_size=step_ns)
    slave = CosimLocalSlave(fmu_path=os.path.abspath(fmu), instance_name="pc")
    idx = ex.add_local_slave(local_slave=slave)
    allvars = {v.name.decode(): v for v in ex.slave_variables(idx)}
    missing = [n for n in names.values() if n not in allvars]
    if missing:
        raise EngineError(f"libcosim sees no variables {missing}; it has {sorted(allvars)}")
    # only the Real outputs (lcp.pivots may be an Integer)
    names = {lab: n for lab, n in names.items() if allvars[n].type == CosimVariableType.REAL.value}
    refs = {n: allvars[n].reference for n in names.values()}
    obs = CosimObserver.create_time_series(buffer_size=n_steps + 10)
    ex.add_observer(observer=obs)
    for n in names.values():
        obs.start_time_series(idx, value_reference=refs[n], variable_type=CosimVariableType.REAL)
    ex.simulate_until(target_time=n_steps * step_ns)
    values = {}
    tt = np.zeros(0)
    for lab, n in names.items():
        times, _steps, vals = obs.time_series_real_samples(idx, value_reference=refs[n], from_step=0,
                                                           sample_count=n_steps + 1)
        values[lab] = np.asarray(vals, dtype=float)
        tt = np.asarray(times, dtype=float) * 1e-9
    return FmuRun(time=tt, values=values, wall_s=time.perf_counter() - t0)
