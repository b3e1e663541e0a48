"""A MOCK of the `periodic-contact` CLI, for testing the validation harness only.

    tools/mock-periodic-contact solve SCENE.toml -o result.json
    tools/mock-periodic-contact fmu SCENE.toml -o NAME.fmu

It answers with this suite's own discrete marchers (so comparisons against them pass trivially)
and, for the FMU, compiles tools/mock_fmu.c (needs gcc) to play the periodic table back. It
exercises the plumbing (scene writing, JSON/FMU contracts, fmpy, libcosimpy, reports, figures);
it validates nothing about the engine. Usage:

    PC_CLI=$PWD/tools/mock-periodic-contact .venv/bin/python -m pytest
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import uuid
import zipfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from harness.scene import system_from_toml  # noqa: E402
from marching.central_difference import march_cds  # noqa: E402
from marching.compliant import march_compliant  # noqa: E402
from marching.exact import linear_discrete  # noqa: E402
from marching.multistep import march_multistep  # noqa: E402
from marching.rigid import march_rigid  # noqa: E402


def periodic(sys_, scheme, k, pairing):
    T = sys_.period
    t = np.arange(k) * T / k
    if sys_.m == 0:
        x, v, a = linear_discrete(sys_, scheme, k)
        return t, x, v, a, np.zeros((0, k))
    if scheme == "fourier":  # not a Fourier solver: the continuous marcher sampled
        r = (march_rigid if sys_.all_rigid else march_compliant)(sys_, tol=1e-10, samples=k)
        z = r.force.copy()
        for ti, i, P in r.impacts:
            z[i, int(round(ti / (T / k))) % k] += P / (T / k)
        return t, r.x, r.v, r.a, z
    if scheme == "cds":
        r = march_cds(sys_, k, pairing=pairing, tol=1e-12)
    else:
        r = march_multistep(sys_, scheme, k, pairing=pairing, tol=1e-12)
    return t, r.x, r.v, r.a, r.force


def solve(scene_path):
    t0 = time.process_time()
    with open(scene_path) as fh:
        sys_, meta = system_from_toml(fh.read())
    disc = meta["discretization"]
    scheme, k, pairing = disc["scheme"], int(disc["steps"]), disc.get("pairing", "same")
    t, x, v, a, z = periodic(sys_, scheme, k, pairing)
    out = meta["output"]
    gap = sys_.gaps(t) - sys_.B @ x if sys_.m else np.zeros((0, k))
    tot = time.process_time() - t0
    return sys_, meta, {
        "period": sys_.period, "steps": k, "scheme": scheme, "pairing": pairing, "effects": [],
        "time": t.tolist(),
        "displacement": {str(d): x[d].tolist() for d in out.get("displacement", range(sys_.n))},
        "velocity": {str(d): v[d].tolist() for d in out.get("velocity", range(sys_.n))},
        "acceleration": {str(d): a[d].tolist() for d in out.get("displacement", range(sys_.n))},
        "contacts": [{"dof": c.dof, "force": z[i].tolist(), "gap": gap[i].tolist()} for i, c in enumerate(sys_.contacts)],
        "lcp": {"size": sys_.m * k, "status": "solved", "pivots": 0, "residual": 0.0},
        "warnings": ["MOCK ENGINE (validation/tools/mock_engine.py): not periodic-contact"],
        "timing_s": {"assembly": 0.0, "lcp": tot, "recovery": 0.0, "total": tot},
    }


def model_description(res, guid):
    k = res["steps"]
    T = res["period"]
    vars_ = [
        ('frequency', 'parameter', 'tunable', f'<Real start="{2 * np.pi / T!r}"/>'),
        ('force_scale', 'parameter', 'tunable', '<Real start="1.0"/>'),
        ('gap_offset', 'parameter', 'tunable', '<Real start="0.0"/>'),
        ('steps', 'parameter', 'fixed', f'<Integer start="{k}"/>'),
        ('scheme', 'parameter', 'fixed', f'<String start="{res["scheme"]}"/>'),
    ]
    outs = [f"displacement[{d}]" for d in res["displacement"]] + [f"velocity[{d}]" for d in res["velocity"]]
    for i in range(len(res["contacts"])):
        outs += [f"contact[{i}].force", f"contact[{i}].gap"]
    outs.append("lcp.residual")
    sv = []
    for vr, (name, caus, var, typ) in enumerate(vars_):
        sv.append(f'<ScalarVariable name="{name}" valueReference="{vr}" causality="{caus}" variability="{var}">{typ}</ScalarVariable>')
    for j, name in enumerate(outs):
        sv.append(f'<ScalarVariable name="{name}" valueReference="{5 + j}" causality="output" variability="continuous" '
                  f'initial="calculated"><Real/></ScalarVariable>')
    sv.append(f'<ScalarVariable name="lcp.pivots" valueReference="{5 + len(outs)}" causality="output" '
              f'variability="discrete" initial="calculated"><Integer/></ScalarVariable>')
    idx = range(len(vars_) + 1, len(vars_) + len(outs) + 2)
    unknowns = "".join(f'<Unknown index="{i}"/>' for i in idx)
    xml = f'''<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="PeriodicContactMock" guid="{guid}" generationTool="validation/tools/mock_engine.py" variableNamingConvention="structured" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="PeriodicContact" canHandleVariableCommunicationStepSize="true" canNotUseMemoryManagementFunctions="true"/>
  <DefaultExperiment startTime="0" stopTime="{3 * T!r}" stepSize="{T / k!r}"/>
  <ModelVariables>
    {chr(10).join(sv)}
  </ModelVariables>
  <ModelStructure>
    <Outputs>{unknowns}</Outputs>
    <InitialUnknowns>{unknowns}</InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
'''
    return xml, outs


def build_fmu(res, fmu_path):
    import fmpy

    guid = "{" + str(uuid.uuid4()) + "}"
    xml, outs = model_description(res, guid)
    k = res["steps"]
    cols = [res["displacement"][d] for d in res["displacement"]] + [res["velocity"][d] for d in res["velocity"]]
    nxv = len(cols)
    for c in res["contacts"]:
        cols += [c["force"], c["gap"]]
    cols.append([res["lcp"]["residual"]] * k)
    table = np.array(cols).T
    with tempfile.TemporaryDirectory() as tmp:
        so = os.path.join(tmp, "PeriodicContact.so")
        inc = os.path.join(os.path.dirname(fmpy.__file__), "c-code")
        subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-I", inc, os.path.join(HERE, "mock_fmu.c"), "-o", so, "-lm"],
                       check=True)
        lines = [f"{k} {res['period']!r} {table.shape[1]} {nxv}"] + [" ".join(repr(float(v)) for v in r) for r in table]
        lines.append(res["scheme"])
        with zipfile.ZipFile(fmu_path, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", xml)
            z.write(so, "binaries/linux64/PeriodicContact.so")
            z.writestr("resources/table.txt", "\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(prog="mock-periodic-contact")
    ap.add_argument("command", choices=["solve", "fmu"])
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    _, _, res = solve(a.scene)
    if a.command == "solve":
        with open(a.output, "w") as fh:
            json.dump(res, fh)
    else:
        build_fmu(res, a.output)


if __name__ == "__main__":
    main()
