"""The FMU under random legal and illegal call sequences, driven through ctypes (issue 7, part 5).

The packaged binary (`binaries/linux64/PeriodicContact.so`) is loaded with ctypes and driven
call by call. Before every call, a model of the FMI 2.0 co-simulation state machine written in
this file (`Model`: the allowed-call table of the FMI 2.0 standard's co-simulation state machine,
§4.2.4, its rules on which variables may be set in which state, and the error policy documented in src/fmi/fmi2/mod.rs)
predicts the status; the FMU must return exactly that status. Sequences are seeded (pytest
parameters), each a few thousand calls over several interleaved instances of two FMUs:

  - `undamped`: an undamped 1-DOF oscillator, fourier, k = 16 (no contact). Its operator is
    exactly singular at frequency 1, so the model can predict the failures: fmi2Error from
    fmi2ExitInitializationMode (and from output reads in initialisation mode), fmi2Discard from
    fmi2DoStep after a tunable change to frequency 1, then stepFailed / fmi2Terminated = true.
  - `compliant`: the compliant-stop example (contact, LCP) with k = 64; every frequency drawn is
    solvable, so every solve is predicted to succeed.

Checked for every call: the status; no getter ever returns NaN/Inf (output buffers are
pre-filled with a finite sentinel, so anything written is checked, also by calls that fail
part-way); parameter/input reads equal the model's values; fmi2GetRealStatus
(fmi2LastSuccessfulTime) and fmi2GetBooleanStatus(fmi2Terminated) equal the model's; every
logged message is passed with the format "%s" and the instance's name; calls with a NULL or a
garbage instance (a buffer of random bytes) return fmi2Error and leave the buffer untouched.
A "probe" call serializes an FMU state and decodes the machine state and time from its header
(SERIAL_HEADER, format and model versions, GUID, state code, time; src/fmi/state.rs and src/fmi/fmi2/instance.rs) to compare them with the model's.

The process must survive (a crash fails the whole pytest run). Needs the CLI and the FMU binary
(`cargo build --release`); skipped without them
unless PC_REQUIRE_BINARIES=1.
"""
from __future__ import annotations

import ctypes
import math
import os
import random
import struct
import zipfile
from ctypes import (CFUNCTYPE, POINTER, Structure, byref, c_char, c_char_p, c_double, c_int,
                    c_size_t, c_uint, c_void_p)

import pytest

from harness import engine

pytestmark = pytest.mark.engine

CALLS_PER_SEED = 3000
SEEDS = [1, 2, 3, 4]

# fmi2Status
OK, WARNING, DISCARD, ERROR, FATAL, PENDING = range(6)
STATUS = ["fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending"]
# fmi2StatusKind
DO_STEP_STATUS, PENDING_STATUS, LAST_SUCCESSFUL_TIME, TERMINATED_KIND = range(4)

# Machine states (names as in src/fmi2/instance.rs) and their codes in a serialized state.
INST, INIT, COMPLETE, FAILED, TERMINATED, ERRSTATE = ("instantiated", "initializationMode",
                                                      "stepComplete", "stepFailed", "terminated",
                                                      "error")
STATE_CODE = {INST: 0, INIT: 1, COMPLETE: 2, FAILED: 3, TERMINATED: 4, ERRSTATE: 5}
ANY = frozenset(STATE_CODE)
GETTERS = frozenset({INIT, COMPLETE, FAILED, TERMINATED, ERRSTATE})
# The allowed-call table (src/formulation.md §1.3). stepInProgress and stepCanceled never occur (this FMU
# never returns fmi2Pending). In the error state only getters (incl. status and derivative
# getters), Reset, FreeInstance, the FMU-state functions and SetDebugLogging are accepted.
ALLOWED = {
    "SetupExperiment": frozenset({INST}),
    "EnterInitializationMode": frozenset({INST}),
    "ExitInitializationMode": frozenset({INIT}),
    "Terminate": frozenset({COMPLETE, FAILED}),
    "Reset": ANY,
    "Get": GETTERS,
    "Set": frozenset({INST, INIT, COMPLETE}),
    "State": ANY,
    "GetDirectionalDerivative": GETTERS,
    "SetRealInputDerivatives": frozenset({INST, INIT, COMPLETE}),
    "GetRealOutputDerivatives": frozenset({COMPLETE, FAILED, TERMINATED, ERRSTATE}),
    "DoStep": frozenset({COMPLETE}),
    "CancelStep": frozenset(),
    "Status": frozenset({COMPLETE, FAILED, TERMINATED, ERRSTATE}),
}
LOG_CATEGORIES = ["logEvents", "logStatusWarning", "logStatusDiscard", "logStatusError",
                  "logStatusFatal", "logAll"]
SENTINEL = 1.25e300
SERIAL_HEADER = b"PCFMUSTA"  # src/fmi/state.rs: magic, then u16 format version and u16 model version
SERIAL_FORMAT = 2

UNDAMPED = """
[structure]
mass = [[1.0]]
stiffness = [[1.0]]
[excitation]
frequency = 0.7
[[force]]
dof = 0
amplitude = 1.0
[discretization]
scheme = "fourier"
steps = 16
"""


def compliant_scene() -> str:
    path = os.path.join(engine.VALIDATION, "..", "fmu", "scenes", "compliant-stop.toml")
    with open(path) as fh:
        return fh.read().replace("steps = 512", "steps = 64")


# Frequencies drawn per FMU; SINGULAR: the ones whose solve fails (ω·p = 1 for some harmonic p).
FMU_CASES = {
    "undamped": dict(scene=UNDAMPED, frequencies=[0.7, 1.3, 1.7, 1.0], singular={1.0},
                     steps=[16, 32]),
    "compliant": dict(scene=None, frequencies=[1.3, 1.2, 1.45, 0.9], singular=set(),
                      steps=[64]),
}

# ----------------------------------------------------------------------------- ctypes binding

LOGGER = CFUNCTYPE(None, c_void_p, c_char_p, c_int, c_char_p, c_char_p, c_char_p)


class Callbacks(Structure):
    _fields_ = [("logger", LOGGER), ("allocateMemory", c_void_p), ("freeMemory", c_void_p),
                ("stepFinished", c_void_p), ("componentEnvironment", c_void_p)]


P = c_void_p
VRS = POINTER(c_uint)
SIGNATURES = {
    "fmi2GetTypesPlatform": (c_char_p, []),
    "fmi2GetVersion": (c_char_p, []),
    "fmi2SetDebugLogging": (c_int, [P, c_int, c_size_t, POINTER(c_char_p)]),
    "fmi2Instantiate": (P, [c_char_p, c_int, c_char_p, c_char_p, POINTER(Callbacks), c_int, c_int]),
    "fmi2FreeInstance": (None, [P]),
    "fmi2SetupExperiment": (c_int, [P, c_int, c_double, c_double, c_int, c_double]),
    "fmi2EnterInitializationMode": (c_int, [P]),
    "fmi2ExitInitializationMode": (c_int, [P]),
    "fmi2Terminate": (c_int, [P]),
    "fmi2Reset": (c_int, [P]),
    "fmi2GetReal": (c_int, [P, VRS, c_size_t, POINTER(c_double)]),
    "fmi2GetInteger": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2GetBoolean": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2GetString": (c_int, [P, VRS, c_size_t, POINTER(c_char_p)]),
    "fmi2SetReal": (c_int, [P, VRS, c_size_t, POINTER(c_double)]),
    "fmi2SetInteger": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2SetBoolean": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2SetString": (c_int, [P, VRS, c_size_t, POINTER(c_char_p)]),
    "fmi2GetFMUstate": (c_int, [P, POINTER(c_void_p)]),
    "fmi2SetFMUstate": (c_int, [P, c_void_p]),
    "fmi2FreeFMUstate": (c_int, [P, POINTER(c_void_p)]),
    "fmi2SerializedFMUstateSize": (c_int, [P, c_void_p, POINTER(c_size_t)]),
    "fmi2SerializeFMUstate": (c_int, [P, c_void_p, POINTER(c_char), c_size_t]),
    "fmi2DeSerializeFMUstate": (c_int, [P, POINTER(c_char), c_size_t, POINTER(c_void_p)]),
    "fmi2GetDirectionalDerivative": (c_int, [P, VRS, c_size_t, VRS, c_size_t, POINTER(c_double),
                                             POINTER(c_double)]),
    "fmi2SetRealInputDerivatives": (c_int, [P, VRS, c_size_t, POINTER(c_int), POINTER(c_double)]),
    "fmi2GetRealOutputDerivatives": (c_int, [P, VRS, c_size_t, POINTER(c_int), POINTER(c_double)]),
    "fmi2DoStep": (c_int, [P, c_double, c_double, c_int]),
    "fmi2CancelStep": (c_int, [P]),
    "fmi2GetStatus": (c_int, [P, c_int, POINTER(c_int)]),
    "fmi2GetRealStatus": (c_int, [P, c_int, POINTER(c_double)]),
    "fmi2GetIntegerStatus": (c_int, [P, c_int, POINTER(c_int)]),
    "fmi2GetBooleanStatus": (c_int, [P, c_int, POINTER(c_int)]),
    "fmi2GetStringStatus": (c_int, [P, c_int, POINTER(c_char_p)]),
}


class Binary:
    """The 34 functions of one unpacked FMU, typed."""

    def __init__(self, so_path: str):
        self.lib = ctypes.CDLL(so_path, mode=os.RTLD_LOCAL | os.RTLD_NOW)
        for name, (res, args) in SIGNATURES.items():
            f = getattr(self.lib, name)
            f.restype = res
            f.argtypes = args
            setattr(self, name[4:], f)


def vr_array(vrs):
    return (c_uint * len(vrs))(*vrs) if vrs else None


class Log:
    def __init__(self):
        self.lines = []
        self.cb = LOGGER(self._log)

    def _log(self, env, instance, status, category, fmt, message):
        self.lines.append((instance.decode() if instance else None, status,
                           category.decode() if category else None,
                           fmt.decode() if fmt else None,
                           message.decode(errors="replace") if message else None))


# ----------------------------------------------------------------------------- the FMUs


class Variable:
    def __init__(self, v):
        self.name = v.name
        self.vr = int(v.valueReference)
        self.type = v.type  # 'Real', 'Integer', ...
        self.causality = v.causality or "local"
        self.variability = v.variability or ("continuous" if v.type == "Real" else "discrete")
        initial = v.initial
        if initial is None:
            # The defaults of the FMI 2.0 table (an input is treated as "exact").
            initial = {"parameter": "exact", "input": "exact", "output": "calculated",
                       "calculatedParameter": "calculated"}.get(self.causality, "calculated")
            if self.variability == "constant":
                initial = "exact"
        self.initial = initial
        if v.start is None:
            self.start = None
        elif v.type == "Real":
            self.start = float(v.start)
        elif v.type == "Boolean":
            self.start = int(v.start == "true")
        else:
            self.start = int(v.start)


class Fmu:
    def __init__(self, name, fmu_path, workdir, case):
        from fmpy import read_model_description

        self.name = name
        self.case = case
        md = read_model_description(fmu_path)
        self.guid = md.guid
        self.vars = [Variable(v) for v in md.modelVariables]
        self.by_vr = {v.vr: v for v in self.vars}
        self.by_name = {v.name: v for v in self.vars}
        unz = os.path.join(workdir, f"{name}_unzipped")
        with zipfile.ZipFile(fmu_path) as z:
            z.extractall(unz)
        self.resources = "file://" + os.path.join(unz, "resources")
        self.bin = Binary(os.path.join(unz, "binaries", "linux64", "PeriodicContact.so"))
        self.max_vr = max(self.by_vr)


# ----------------------------------------------------------------------------- the model


def same_time(a, b, h):
    """The communication-point tolerance (fmi2.md §1.2: never ==)."""
    return abs(a - b) <= 1e-9 * max(abs(a), abs(b), 1.0) + 1e-6 * abs(h)


class Clock:
    def __init__(self):
        self.state = INST
        self.time = 0.0
        self.start = 0.0
        self.stop = None
        self.last_successful = 0.0
        self.terminate_requested = False

    def copy(self):
        c = Clock()
        c.__dict__.update(self.__dict__)
        return c


class Model:
    """The predicted behaviour of one instance."""

    def __init__(self, fmu: Fmu):
        self.fmu = fmu
        self.clock = Clock()
        self.values = {v.vr: v.start for v in fmu.vars if v.causality in ("parameter", "input")}
        self.initialized = False

    # -- what the model knows about the scene
    def effective_frequency(self):
        w = self.values[self.fmu.by_name["frequency"].vr]
        w_in = self.values[self.fmu.by_name["frequency_in"].vr]
        return w_in if w_in > 0 else w

    def solvable(self):
        return self.effective_frequency() not in self.fmu.case["singular"]

    def allowed(self, group):
        return self.clock.state in ALLOWED[group]

    def fail(self):
        self.clock.state = ERRSTATE
        return ERROR

    def settable(self, v: Variable):
        s = self.clock.state
        if s == INST:
            return v.variability != "constant" and v.initial in ("exact", "approx")
        if s == INIT:
            return v.causality == "input" or (v.variability != "constant" and v.initial == "exact")
        return v.causality == "input" or (v.causality == "parameter" and v.variability == "tunable")

    @staticmethod
    def in_domain(v: Variable, value):
        if v.type == "Real":
            if not math.isfinite(value):
                return False
            if v.name == "frequency":
                return value > 0
            if v.name == "frequency_in":
                return value >= 0
            return True
        if v.name == "steps":
            return 4 <= value <= 1 << 22
        if v.name == "scheme":
            return 1 <= value <= 5
        if v.name == "polish":
            # fmi2Boolean: any value is one (non-zero is true).
            return True
        return False

    def snapshot(self):
        return (self.clock.copy(), dict(self.values), self.initialized)

    def restore(self, snap):
        clock, values, initialized = snap
        self.clock = clock.copy()
        self.values = dict(values)
        self.initialized = initialized

    def reset(self):
        self.__init__(self.fmu)


# ----------------------------------------------------------------------------- the driver


class Mismatch(AssertionError):
    pass


class Driver:
    def __init__(self, fmus, seed):
        self.fmus = fmus
        self.rng = random.Random(seed)
        self.seed = seed
        self.instances = []  # [fmu, handle, model, log, name]
        self.states = []  # [fmu, c_void_p, snapshot]: live FMU states
        self.garbage = ctypes.create_string_buffer(bytes(self.rng.getrandbits(8) for _ in range(1 << 16)),
                                                   1 << 16)
        self.garbage_copy = self.garbage.raw
        self.history = []
        self.counts = {}
        self.n_instantiated = 0

    # -- bookkeeping
    def record(self, what, expected, got, inst=None):
        self.history.append(f"{what} -> {STATUS[got] if 0 <= got < 6 else got}")
        self.counts[(what.split("(")[0], got)] = self.counts.get((what.split("(")[0], got), 0) + 1
        if expected is not None and got != expected:
            tail = "\n".join(self.history[-25:])
            log = "" if inst is None else "\n".join(map(str, inst[3].lines[-5:]))
            raise Mismatch(f"seed {self.seed}, call {len(self.history)}: {what}: expected "
                           f"{STATUS[expected]}, FMU returned {STATUS[got] if 0 <= got < 6 else got}\n"
                           f"last calls:\n{tail}\nlast log lines:\n{log}")

    def check_finite(self, what, values):
        for x in values:
            if not math.isfinite(x):
                raise Mismatch(f"seed {self.seed}, call {len(self.history)}: {what} wrote {x}")

    def instantiate(self, fmu, wrong_guid=False):
        log = Log()
        cb = Callbacks(log.cb, None, None, None, None)
        name = f"{fmu.name}-{self.n_instantiated} %s%n"
        self.n_instantiated += 1
        guid = "{00000000-0000-0000-0000-000000000000}" if wrong_guid else fmu.guid
        c = fmu.bin.Instantiate(name.encode(), 1, guid.encode(), fmu.resources.encode(), byref(cb),
                                0, self.rng.choice([0, 1]))
        what = f"fmi2Instantiate({fmu.name}, {'wrong GUID' if wrong_guid else 'GUID'})"
        self.history.append(f"{what} -> {'NULL' if not c else 'instance'}")
        if wrong_guid:
            if c:
                raise Mismatch(f"{what}: a wrong GUID gave an instance")
            assert any("GUID mismatch" in (l[4] or "") for l in log.lines), log.lines
            return
        if not c:
            raise Mismatch(f"{what}: NULL; log {log.lines}")
        self.instances.append([fmu, c, Model(fmu), log, name, cb])

    def free(self, inst):
        inst[0].bin.FreeInstance(inst[1])
        self.history.append(f"fmi2FreeInstance({inst[4]})")
        self.check_log(inst)
        self.instances.remove(inst)

    def check_log(self, inst):
        for (instance, status, category, fmt, message) in inst[3].lines:
            if fmt != "%s" or instance != inst[4] or category not in LOG_CATEGORIES:
                raise Mismatch(f"bad log line {(instance, status, category, fmt, message)}")
        inst[3].lines.clear()

    # -- one random call
    def step(self):
        r = self.rng.random()
        live = [i for i in self.instances]
        if not live or r < 0.01:
            if len(self.instances) < 4:
                self.instantiate(self.rng.choice(self.fmus), wrong_guid=self.rng.random() < 0.1)
            return
        inst = self.rng.choice(live)
        if r < 0.02:
            self.free(inst)
            return
        if r < 0.04:
            self.bad_handle(inst[0])
            return
        op = self.rng.choice(OPS)
        op(self, inst)
        if len(inst[3].lines) > 50:
            self.check_log(inst)

    def bad_handle(self, fmu):
        """NULL and garbage instances: fmi2Error everywhere, nothing written through them."""
        b = fmu.bin
        h = self.rng.choice([None, ctypes.addressof(self.garbage)])
        which = "NULL" if h is None else "garbage"
        vr = vr_array([0])
        d = (c_double * 1)(SENTINEL)
        i = (c_int * 1)(7)
        st = c_void_p()
        size = c_size_t(0)
        calls = [
            lambda: b.SetDebugLogging(h, 1, 0, None),
            lambda: b.SetupExperiment(h, 0, 0.0, 0.0, 0, 0.0),
            lambda: b.EnterInitializationMode(h),
            lambda: b.ExitInitializationMode(h),
            lambda: b.Terminate(h),
            lambda: b.Reset(h),
            lambda: b.GetReal(h, vr, 1, d),
            lambda: b.GetInteger(h, vr, 1, i),
            lambda: b.SetReal(h, vr, 1, d),
            lambda: b.SetInteger(h, vr, 1, i),
            lambda: b.GetFMUstate(h, byref(st)),
            lambda: b.SetFMUstate(h, None),
            lambda: b.FreeFMUstate(h, byref(st)),
            lambda: b.SerializedFMUstateSize(h, None, byref(size)),
            lambda: b.DoStep(h, 0.0, 0.1, 1),
            lambda: b.CancelStep(h),
            lambda: b.GetRealStatus(h, LAST_SUCCESSFUL_TIME, d),
            lambda: b.GetBooleanStatus(h, TERMINATED_KIND, i),
            lambda: b.GetRealOutputDerivatives(h, vr, 1, (c_int * 1)(1), d),
        ]
        for k in self.rng.sample(range(len(calls)), 3):
            self.record(f"bad handle {which} #{k}", ERROR, calls[k]())
        b.FreeInstance(h)
        if d[0] != SENTINEL or i[0] != 7 or st.value is not None or size.value != 0:
            raise Mismatch(f"a call with a {which} instance wrote an output")
        if self.garbage.raw != self.garbage_copy:
            raise Mismatch("a call with a garbage instance wrote into it")


# Each op: (driver, instance) -> None. It predicts, calls, and records.


def op_setup(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    start = d.rng.choice([0.0, 0.0, 1.5, -2.0, float("nan")])
    stop_defined = d.rng.random() < 0.4
    stop = d.rng.choice([start + 1e9, start + 0.5, start - 1.0]) if stop_defined else 0.0
    if not m.allowed("SetupExperiment"):
        exp = m.fail()
    elif not math.isfinite(start) or (stop_defined and not stop >= start):
        exp = m.fail()
    else:
        exp = OK
        m.clock.start = m.clock.time = start
        m.clock.stop = stop if stop_defined else None
    d.record(f"fmi2SetupExperiment({start}, stop={stop if stop_defined else None})", exp,
             fmu.bin.SetupExperiment(c, d.rng.choice([0, 1]), 1e-6, start, int(stop_defined), stop),
             inst)


def op_enter(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    if m.allowed("EnterInitializationMode"):
        exp = OK
        m.clock.state = INIT
        m.clock.time = m.clock.start
    else:
        exp = m.fail()
    d.record("fmi2EnterInitializationMode", exp, fmu.bin.EnterInitializationMode(c), inst)


def op_exit(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    if not m.allowed("ExitInitializationMode"):
        exp = m.fail()
    elif not m.solvable():
        exp = m.fail()
    else:
        exp = OK
        m.initialized = True
        m.clock.state = COMPLETE
        m.clock.time = m.clock.last_successful = m.clock.start
    d.record(f"fmi2ExitInitializationMode(w={m.effective_frequency()})", exp,
             fmu.bin.ExitInitializationMode(c), inst)


def op_init_all(d: Driver, inst):
    """A legal initialisation from wherever the instance is (Reset first when needed)."""
    if inst[2].clock.state != INST:
        op_reset(d, inst)
    if d.rng.random() < 0.5:
        m = inst[2]
        start = d.rng.choice([0.0, 1.5, -2.0])
        stop = d.rng.choice([None, start + 1e9, start + 2.0])
        m.clock.start = m.clock.time = start
        m.clock.stop = stop
        d.record(f"fmi2SetupExperiment({start}, stop={stop})", OK,
                 inst[0].bin.SetupExperiment(inst[1], 0, 0.0, start, int(stop is not None),
                                             stop if stop is not None else 0.0), inst)
    if d.rng.random() < 0.5:
        op_set_random(d, inst, legal=True)
    op_enter(d, inst)
    if d.rng.random() < 0.3:
        op_set_random(d, inst, legal=True)
    op_exit(d, inst)


def op_terminate(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    if m.allowed("Terminate"):
        exp = OK
        m.clock.state = TERMINATED
    else:
        exp = m.fail()
    d.record("fmi2Terminate", exp, fmu.bin.Terminate(c), inst)


def op_reset(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    m.reset()
    d.record("fmi2Reset", OK, fmu.bin.Reset(c), inst)


def op_debug_logging(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    kind = d.rng.random()
    if kind < 0.6:
        cats = d.rng.sample(LOG_CATEGORIES, d.rng.randint(0, 3))
        exp = OK
    elif kind < 0.85:
        cats = [d.rng.choice(LOG_CATEGORIES), "logNonsense%s%n"]
        exp = ERROR  # unknown category: fmi2Error, the state is kept
    else:
        arr = (c_char_p * 2)(b"logAll", None)  # a NULL category: a bad argument
        exp = m.fail()
        d.record("fmi2SetDebugLogging(NULL category)", exp, fmu.bin.SetDebugLogging(c, 1, 2, arr), inst)
        return
    arr = (c_char_p * max(len(cats), 1))(*[x.encode() for x in cats])
    d.record(f"fmi2SetDebugLogging({cats})", exp,
             fmu.bin.SetDebugLogging(c, d.rng.choice([0, 1]), len(cats), arr if cats else None), inst)


def random_vrs(d: Driver, fmu: Fmu, n):
    out = []
    for _ in range(n):
        if d.rng.random() < 0.05:
            out.append(d.rng.choice([fmu.max_vr + 1, 9999, 2**32 - 1]))
        else:
            out.append(d.rng.choice(fmu.vars).vr)
    return out


def op_get(d: Driver, inst, kind=None):
    fmu, c, m = inst[0], inst[1], inst[2]
    kind = kind or d.rng.choice(["Real", "Real", "Real", "Integer", "Boolean", "String"])
    n = d.rng.choice([0, 1, 1, 2, 3])
    vrs = random_vrs(d, fmu, n)
    if kind == "Real":
        buf = (c_double * max(n, 1))(*([SENTINEL] * max(n, 1)))
    elif kind in ("Integer", "Boolean"):
        buf = (c_int * max(n, 1))(*([-7] * max(n, 1)))
    else:
        buf = (c_char_p * max(n, 1))()
    null_values = n > 0 and d.rng.random() < 0.03
    # Prediction.
    exp, reads = OK, []
    if not m.allowed("Get"):
        exp = m.fail()
    elif null_values:
        exp = m.fail()
    else:
        for vr in vrs:
            v = fmu.by_vr.get(vr)
            if v is None or v.type != kind:
                exp = m.fail()
                break
            if v.causality == "output" and not m.initialized and not m.solvable():
                exp = m.fail()  # outputs before initialisation are solved on demand
                break
            reads.append(v)
    f = getattr(fmu.bin, f"Get{kind}")
    got = f(c, vr_array(vrs), n, None if null_values else buf)
    d.record(f"fmi2Get{kind}({[fmu.by_vr[v].name if v in fmu.by_vr else v for v in vrs]})", exp, got,
             inst)
    if kind == "Real":
        d.check_finite("fmi2GetReal", buf[:n])
    if got == OK:
        for j, v in enumerate(reads):
            if v.causality in ("parameter", "input"):
                want = m.values[v.vr]
                if buf[j] != want:
                    raise Mismatch(f"seed {d.seed}: {v.name} read {buf[j]}, set {want}")


def op_set_random(d: Driver, inst, legal=False):
    fmu, c, m = inst[0], inst[1], inst[2]
    kind = "Real" if legal else d.rng.choice(["Real", "Real", "Real", "Integer", "Integer", "Boolean", "String"])
    candidates = [v for v in fmu.vars if v.type == kind] or fmu.vars
    if legal:
        candidates = [v for v in candidates if m.settable(v)] or candidates
    n = 1 if legal else d.rng.choice([0, 1, 1, 2])
    chosen = [d.rng.choice(candidates) for _ in range(n)]
    vrs = [v.vr for v in chosen]
    if not legal and n and d.rng.random() < 0.05:
        vrs[-1] = d.rng.choice([fmu.max_vr + 1, 9999])
    values = []
    for v in chosen:
        if kind == "Real":
            if v.name.startswith("frequency"):
                pool = fmu.case["frequencies"] + ([0.0] if v.name == "frequency_in" else [])
                if not legal:
                    pool = pool + [-1.0, 0.0, float("nan"), float("inf")]
                values.append(d.rng.choice(pool))
            else:
                pool = [1.0, 0.5, 2.0, -0.3, 0.1, 0.0]
                if not legal:
                    pool = pool + [float("nan"), float("-inf")]
                values.append(d.rng.choice(pool))
        elif kind == "Integer":
            if v.name == "steps":
                values.append(d.rng.choice(fmu.case["steps"] + [2, -1]))
            elif v.name == "scheme":
                values.append(d.rng.choice([5, 5, 0, 9]))
            else:
                values.append(d.rng.choice([0, 1, 100]))
        else:
            values.append(1)
    null_values = n > 0 and not legal and d.rng.random() < 0.03
    # Prediction: checked and applied in order; the first failure stops the call.
    if not m.allowed("Set"):
        exp = m.fail()
    elif null_values:
        exp = m.fail()
    else:
        exp = OK
        for vr, value in zip(vrs, values):
            v = fmu.by_vr.get(vr)
            if v is None or v.type != kind or not m.settable(v) or not m.in_domain(v, value):
                exp = m.fail()
                break
            m.values[vr] = value
    if kind == "Real":
        arr = (c_double * max(n, 1))(*(values or [0.0]))
    elif kind in ("Integer", "Boolean"):
        arr = (c_int * max(n, 1))(*(values or [0]))
    else:
        arr = (c_char_p * max(n, 1))(*([b"x"] * max(n, 1)))
    f = getattr(fmu.bin, f"Set{kind}")
    got = f(c, vr_array(vrs), n, None if null_values else arr)
    d.record(f"fmi2Set{kind}({[(fmu.by_vr[v].name if v in fmu.by_vr else v) for v in vrs]}={values})",
             exp, got, inst)


def op_set(d: Driver, inst):
    op_set_random(d, inst, legal=d.rng.random() < 0.6)


def op_do_step(d: Driver, inst, n=None):
    fmu, c, m = inst[0], inst[1], inst[2]
    for _ in range(n or d.rng.choice([1, 1, 3, 10])):
        h = d.rng.choice([0.05, 0.1, 0.013, 0.05])
        r = d.rng.random()
        if r < 0.85:
            t = m.clock.time
        elif r < 0.9:
            t = m.clock.time + 1e-12  # round-off of the master: accepted
        elif r < 0.95:
            t = m.clock.time + 0.5  # a gap in time: refused
        else:
            t, h = m.clock.time, d.rng.choice([0.0, -0.1, float("nan"), float("inf")])
        if not m.allowed("DoStep"):
            exp = m.fail()
        elif not (math.isfinite(t) and math.isfinite(h) and h > 0):
            exp = m.fail()
        elif not same_time(t, m.clock.time, h):
            exp = m.fail()
        elif m.clock.stop is not None and t + h > m.clock.stop and not same_time(t + h, m.clock.stop, h):
            exp = m.fail()
        elif not m.solvable():
            exp = DISCARD
            m.clock.state = FAILED
            m.clock.time = m.clock.last_successful = t
            m.clock.terminate_requested = True
        else:
            exp = OK
            m.clock.time = m.clock.last_successful = t + h
        d.record(f"fmi2DoStep({t}, {h}, w={m.effective_frequency()})", exp, fmu.bin.DoStep(c, t, h, 1), inst)
        if exp != OK:
            return


def op_step_run(d: Driver, inst):
    """Mostly legal traffic: initialise if needed, then a run of steps with output reads."""
    if inst[2].clock.state != COMPLETE:
        op_init_all(d, inst)
    for _ in range(d.rng.randint(1, 8)):
        if inst[2].clock.state != COMPLETE:
            return
        op_do_step(d, inst, n=1)
        op_get(d, inst, kind="Real")
    if d.rng.random() < 0.2:
        op_terminate(d, inst)


def op_retune(d: Driver, inst):
    """A tunable parameter or an input changed during the simulation, then steps (re-solves,
    which fail exactly at the singular frequencies: fmi2Discard)."""
    fmu, c, m = inst[0], inst[1], inst[2]
    if m.clock.state != COMPLETE:
        op_init_all(d, inst)
    if m.clock.state != COMPLETE:
        return
    names = [v for v in ("frequency", "frequency_in", "force_scale", "force_scale_in", "gap_offset")
             if v in fmu.by_name]
    v = fmu.by_name[d.rng.choice(names) if d.rng.random() < 0.4 else d.rng.choice(["frequency", "frequency_in"])]
    if v.name.startswith("frequency"):
        value = d.rng.choice(fmu.case["frequencies"] + ([0.0] if v.name == "frequency_in" else []))
    else:
        value = d.rng.choice([0.5, 1.0, 2.0, -0.1])
    m.values[v.vr] = value
    d.record(f"fmi2SetReal({v.name}={value})", OK,
             fmu.bin.SetReal(c, vr_array([v.vr]), 1, (c_double * 1)(value)), inst)
    op_do_step(d, inst, n=d.rng.randint(1, 3))
    if m.clock.state in (COMPLETE, FAILED):
        op_status(d, inst)
    if m.clock.state == FAILED:
        d.rng.choice([op_terminate, op_terminate, op_get, op_do_step, op_fmu_state])(d, inst)


def op_status(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    fn = d.rng.choice(["Status", "RealStatus", "IntegerStatus", "BooleanStatus", "StringStatus"])
    kind = d.rng.choice([DO_STEP_STATUS, PENDING_STATUS, LAST_SUCCESSFUL_TIME, TERMINATED_KIND,
                         LAST_SUCCESSFUL_TIME, TERMINATED_KIND, -1, 7])
    buf = {"Status": (c_int * 1)(-7), "RealStatus": (c_double * 1)(SENTINEL),
           "IntegerStatus": (c_int * 1)(-7), "BooleanStatus": (c_int * 1)(-7),
           "StringStatus": (c_char_p * 1)()}[fn]
    null = d.rng.random() < 0.03
    if null:
        exp = m.fail()
    elif not m.allowed("Status"):
        exp = m.fail()
    elif not 0 <= kind <= 3:
        exp = m.fail()
    elif (fn, kind) in (("RealStatus", LAST_SUCCESSFUL_TIME), ("BooleanStatus", TERMINATED_KIND)):
        exp = OK
    else:
        exp = DISCARD  # a status kind this FMU does not provide
    got = getattr(fmu.bin, f"Get{fn}")(c, kind, None if null else buf)
    d.record(f"fmi2Get{fn}({kind})", exp, got, inst)
    if fn == "RealStatus":
        d.check_finite("fmi2GetRealStatus", buf[:1])
    if got == OK and fn == "RealStatus" and buf[0] != m.clock.last_successful:
        raise Mismatch(f"seed {d.seed}: fmi2LastSuccessfulTime {buf[0]} vs model {m.clock.last_successful}")
    if got == OK and fn == "BooleanStatus" and buf[0] != int(m.clock.terminate_requested):
        raise Mismatch(f"seed {d.seed}: fmi2Terminated {buf[0]} vs model {m.clock.terminate_requested}")


def op_derivatives(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    which = d.rng.choice(["output", "output", "input", "directional"])
    if which == "output":
        n = d.rng.choice([1, 2])
        outputs = [v.vr for v in fmu.vars if v.causality == "output" and v.type == "Real"]
        vrs = [d.rng.choice(outputs) for _ in range(n)] if d.rng.random() < 0.7 else random_vrs(d, fmu, n)
        orders = [d.rng.choice([1] * 12 + [2, 0]) for _ in vrs]
        buf = (c_double * n)(*([SENTINEL] * n))
        if not m.allowed("GetRealOutputDerivatives"):
            exp = m.fail()
        else:
            exp = OK
            for vr, o in zip(vrs, orders):
                v = fmu.by_vr.get(vr)
                if v is None or v.type != "Real" or v.causality != "output" or o != 1:
                    exp = m.fail()
                    break
        got = fmu.bin.GetRealOutputDerivatives(c, vr_array(vrs), n, (c_int * n)(*orders), buf)
        d.record(f"fmi2GetRealOutputDerivatives({vrs}, {orders})", exp, got, inst)
        d.check_finite("fmi2GetRealOutputDerivatives", buf[:n])
    elif which == "input":
        exp = ERROR
        if not m.allowed("SetRealInputDerivatives"):
            m.fail()
        vr = vr_array([0])
        got = fmu.bin.SetRealInputDerivatives(c, vr, 1, (c_int * 1)(1), (c_double * 1)(1.0))
        d.record("fmi2SetRealInputDerivatives", exp, got, inst)
    else:
        exp = ERROR
        if not m.allowed("GetDirectionalDerivative"):
            m.fail()
        vr = vr_array([0])
        out = (c_double * 1)(SENTINEL)
        got = fmu.bin.GetDirectionalDerivative(c, vr, 1, vr, 1, (c_double * 1)(1.0), out)
        d.record("fmi2GetDirectionalDerivative", exp, got, inst)
        d.check_finite("fmi2GetDirectionalDerivative", out[:1])


def op_cancel(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    exp = m.fail()  # only legal in stepInProgress, which never occurs
    d.record("fmi2CancelStep", exp, fmu.bin.CancelStep(c), inst)


def op_fmu_state(d: Driver, inst):
    fmu, c, m = inst[0], inst[1], inst[2]
    r = d.rng.random()
    mine = [s for s in d.states if s[0] is fmu]
    if r < 0.3 or not mine:
        st = c_void_p()
        d.record("fmi2GetFMUstate(new)", OK, fmu.bin.GetFMUstate(c, byref(st)), inst)
        if not st.value:
            raise Mismatch("fmi2GetFMUstate gave NULL")
        d.states.append([fmu, st, m.snapshot()])
    elif r < 0.4:
        s = d.rng.choice(mine)
        d.record("fmi2GetFMUstate(overwrite)", OK, fmu.bin.GetFMUstate(c, byref(s[1])), inst)
        s[2] = m.snapshot()
    elif r < 0.65:
        s = d.rng.choice(d.states)
        if s[0] is fmu:
            m.restore(s[2])
            exp = OK
        else:
            exp = m.fail()  # a state of another FMU (GUID mismatch)
        d.record("fmi2SetFMUstate", exp, fmu.bin.SetFMUstate(c, s[1]), inst)
    elif r < 0.75:
        s = d.rng.choice(mine)
        d.record("fmi2FreeFMUstate", OK, fmu.bin.FreeFMUstate(c, byref(s[1])), inst)
        if s[1].value is not None:
            raise Mismatch("fmi2FreeFMUstate did not set the state to NULL")
        d.states.remove(s)
    elif r < 0.9:
        # Serialize, deserialize (sometimes truncated or corrupted), probe the header.
        s = d.rng.choice(mine)
        size = c_size_t(0)
        d.record("fmi2SerializedFMUstateSize", OK, fmu.bin.SerializedFMUstateSize(c, s[1], byref(size)), inst)
        buf = (c_char * size.value)()
        small = d.rng.random() < 0.1
        exp = m.fail() if small else OK
        d.record("fmi2SerializeFMUstate" + (" (buffer too small)" if small else ""), exp,
                 fmu.bin.SerializeFMUstate(c, s[1], buf, size.value - 1 if small else size.value), inst)
        if small:
            return
        data = bytes(buf)
        check_header(d, fmu, data, s[2][0])
        corrupt = d.rng.random() < 0.2
        if corrupt:
            data = data[: d.rng.randint(0, len(data) - 1)]
        new = c_void_p()
        exp = m.fail() if corrupt else OK
        d.record("fmi2DeSerializeFMUstate" + (" (truncated)" if corrupt else ""), exp,
                 fmu.bin.DeSerializeFMUstate(c, data, len(data), byref(new)), inst)
        if not corrupt:
            d.states.append([fmu, new, (s[2][0].copy(), dict(s[2][1]), s[2][2])])
        elif new.value is not None:
            raise Mismatch("a failed fmi2DeSerializeFMUstate returned a state")
    else:
        # Bad state pointers: NULL, garbage, a NULL FMUstate* argument.
        kind = d.rng.choice(["set NULL", "set garbage", "get NULL*", "get garbage", "free garbage",
                             "size garbage"])
        g = c_void_p(ctypes.addressof(d.garbage))
        size = c_size_t(0)
        exp = m.fail()
        got = {
            "set NULL": lambda: fmu.bin.SetFMUstate(c, None),
            "set garbage": lambda: fmu.bin.SetFMUstate(c, g),
            "get NULL*": lambda: fmu.bin.GetFMUstate(c, None),
            "get garbage": lambda: fmu.bin.GetFMUstate(c, byref(g)),
            "free garbage": lambda: fmu.bin.FreeFMUstate(c, byref(g)),
            "size garbage": lambda: fmu.bin.SerializedFMUstateSize(c, g, byref(size)),
        }[kind]()
        d.record(f"FMU state: {kind}", exp, got, inst)
        if d.garbage.raw != d.garbage_copy:
            raise Mismatch("a garbage FMU state was written to")


def check_header(d: Driver, fmu: Fmu, data: bytes, clock: Clock):
    """The machine state and time in a serialized state equal the model's at capture time."""
    assert data[:8] == SERIAL_HEADER, data[:8]
    (version, _model_version, n) = struct.unpack_from("<HHQ", data, 8)
    assert version == SERIAL_FORMAT, version
    guid = data[20:20 + n].decode()
    state, time = struct.unpack_from("<Bd", data, 20 + n)
    if guid != fmu.guid or state != STATE_CODE[clock.state] or time != clock.time:
        raise Mismatch(f"seed {d.seed}: serialized state {state} at t={time} (GUID {guid}); model "
                       f"{clock.state} ({STATE_CODE[clock.state]}) at t={clock.time}")


def op_probe(d: Driver, inst):
    """The instance's own machine state, read back from a fresh serialized FMU state."""
    fmu, c, m = inst[0], inst[1], inst[2]
    st = c_void_p()
    d.record("probe: fmi2GetFMUstate", OK, fmu.bin.GetFMUstate(c, byref(st)), inst)
    size = c_size_t(0)
    d.record("probe: fmi2SerializedFMUstateSize", OK, fmu.bin.SerializedFMUstateSize(c, st, byref(size)), inst)
    buf = (c_char * size.value)()
    d.record("probe: fmi2SerializeFMUstate", OK, fmu.bin.SerializeFMUstate(c, st, buf, size.value), inst)
    d.record("probe: fmi2FreeFMUstate", OK, fmu.bin.FreeFMUstate(c, byref(st)), inst)
    check_header(d, fmu, bytes(buf), m.clock)


OPS = ([op_setup, op_enter, op_exit, op_terminate, op_debug_logging, op_cancel] +
       [op_reset] * 2 + [op_init_all] * 2 + [op_get] * 5 + [op_set] * 4 + [op_do_step] * 5 +
       [op_step_run] * 4 + [op_retune] * 4 + [op_status] * 2 + [op_derivatives] * 2 + [op_fmu_state] * 3 +
       [op_probe] * 2)


# ----------------------------------------------------------------------------- the tests


@pytest.fixture(scope="module")
def stress_fmus(cli, workdir):
    out = []
    for name, case in FMU_CASES.items():
        text = case["scene"] or compliant_scene()
        path = engine.build_fmu(cli, text, workdir, f"stress_{name}")
        out.append(Fmu(name, path, workdir, case))
    return out


def test_version_and_platform_need_no_instance(stress_fmus):
    for fmu in stress_fmus:
        assert fmu.bin.GetVersion() == b"2.0"
        assert fmu.bin.GetTypesPlatform() == b"default"


@pytest.mark.parametrize("seed", SEEDS)
def test_random_call_sequences_agree_with_the_state_machine_model(stress_fmus, seed):
    d = Driver(stress_fmus, seed)
    try:
        while len(d.history) < CALLS_PER_SEED:
            d.step()
    finally:
        for inst in list(d.instances):
            d.free(inst)
        for fmu, st, _ in d.states:
            # States outlive their instance; free them through a fresh instance of their FMU.
            d.instantiate(fmu)
            inst = d.instances[-1]
            fmu.bin.FreeFMUstate(inst[1], byref(st))
            d.free(inst)
    statuses = {}
    for (what, got), n in d.counts.items():
        statuses[STATUS[got] if 0 <= got < 6 else got] = statuses.get(STATUS[got] if 0 <= got < 6 else got, 0) + n
    print(f"seed {seed}: {len(d.history)} calls, {d.n_instantiated} instantiations; statuses {statuses}")
    # The sequences must have reached the interesting places, not only errors.
    seen = {what for (what, got) in d.counts if got == OK}
    for must in ("fmi2DoStep", "fmi2GetReal", "fmi2ExitInitializationMode", "fmi2SetFMUstate",
                 "fmi2DeSerializeFMUstate", "fmi2Terminate"):
        assert must in seen, f"seed {seed}: no successful {must}; {sorted(seen)}"
    assert any(what == "fmi2DoStep" and got == DISCARD for (what, got) in d.counts), \
        f"seed {seed}: no fmi2Discard seen"
    assert sum(n for (w, got), n in d.counts.items() if w == "fmi2DoStep" and got == OK) >= 200
