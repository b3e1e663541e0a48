"""Builds FrequencyRamp.fmu, the driver component of the drop-in demo (FMI 2.0 co-simulation).

    python build_ramp.py OUT.fmu

ramp_fmu.c (next to this file) is compiled with the system C compiler (`CC`, default `cc`)
against the FMI 2.0 headers that fmpy ships (fmpy/c-code), and zipped with its
modelDescription.xml into binaries/linux64/FrequencyRamp.so. Linux x86-64 only, like the
periodic-contact FMU. fmpy's own FMU template (fmpy.template) writes FMI 3 source FMUs only, and
libcosim 0.0.6 imports FMI 1/2, hence this small hand-written source.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.join(HERE, "ramp_fmu.c")
MODEL_IDENTIFIER = "FrequencyRamp"
GUID = "{8c4e3d7a-5b1f-4c2e-9a6d-0d3e5f7a9b10}"  # must equal GUID in ramp_fmu.c

MODEL_DESCRIPTION = f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{MODEL_IDENTIFIER}" guid="{GUID}"
  description="Linear run-up of a frequency: f_start until t_start, then linear to f_end at t_end, then held"
  generationTool="periodic-contact validation/demo/build_ramp.py" variableNamingConvention="flat" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"
    canGetAndSetFMUstate="false" canSerializeFMUstate="false" providesDirectionalDerivative="false"
    canInterpolateInputs="false" maxOutputDerivativeOrder="1"/>
  <UnitDefinitions>
    <Unit name="rad/s"><BaseUnit rad="1" s="-1"/></Unit>
    <Unit name="s"><BaseUnit s="1"/></Unit>
  </UnitDefinitions>
  <LogCategories>
    <Category name="logStatusError" description="Errors"/>
  </LogCategories>
  <ModelVariables>
    <ScalarVariable name="f_start" valueReference="0" causality="parameter" variability="fixed" initial="exact" description="Frequency before and at t_start">
      <Real start="1.0" unit="rad/s"/>
    </ScalarVariable>
    <ScalarVariable name="f_end" valueReference="1" causality="parameter" variability="fixed" initial="exact" description="Frequency at and after t_end">
      <Real start="2.0" unit="rad/s"/>
    </ScalarVariable>
    <ScalarVariable name="t_start" valueReference="2" causality="parameter" variability="fixed" initial="exact" description="Start of the ramp">
      <Real start="0.0" unit="s"/>
    </ScalarVariable>
    <ScalarVariable name="t_end" valueReference="3" causality="parameter" variability="fixed" initial="exact" description="End of the ramp">
      <Real start="1.0" unit="s"/>
    </ScalarVariable>
    <ScalarVariable name="frequency" valueReference="4" causality="output" variability="continuous" initial="calculated" description="The driven frequency">
      <Real unit="rad/s"/>
    </ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs>
      <Unknown index="5" dependencies=""/>
    </Outputs>
    <InitialUnknowns>
      <Unknown index="5" dependencies="1 2 3 4"/>
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"""


def fmi2_headers() -> str:
    import fmpy

    d = os.path.join(os.path.dirname(fmpy.__file__), "c-code")
    if not os.path.exists(os.path.join(d, "fmi2Functions.h")):
        raise RuntimeError(f"fmpy's FMI 2 headers not found in {d}")
    return d


def build(out: str) -> str:
    """Compiles and packages the ramp FMU at `out`; returns its absolute path."""
    cc = os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        raise RuntimeError(f"C compiler {cc!r} not found (set CC)")
    out = os.path.abspath(out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        so = os.path.join(tmp, f"{MODEL_IDENTIFIER}.so")
        cmd = [cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC", "-fvisibility=default",
               "-I", fmi2_headers(), SOURCE, "-o", so]
        cp = subprocess.run(cmd, capture_output=True, text=True)
        if cp.returncode != 0:
            raise RuntimeError(f"compiling the ramp FMU failed: {' '.join(cmd)}\n{cp.stderr}")
        with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", MODEL_DESCRIPTION)
            z.write(so, f"binaries/linux64/{MODEL_IDENTIFIER}.so")
            z.write(SOURCE, f"sources/{os.path.basename(SOURCE)}")
    return out


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    print(build(sys.argv[1]))
