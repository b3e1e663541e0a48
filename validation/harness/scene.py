"""Scene files (TOML text, the contract of `periodic-contact solve`) written from a System."""
from __future__ import annotations

import math

import numpy as np

from marching.model import System


def _num(v) -> str:
    v = float(v)
    if not math.isfinite(v):
        raise ValueError("scene values must be finite")
    if v == int(v) and abs(v) < 1e15:
        return f"{v:.1f}"
    return repr(v)  # shortest round-trip repr is valid TOML (e.g. 1e-05, 0.3)


def _matrix(a: np.ndarray) -> str:
    return "[" + ", ".join("[" + ", ".join(_num(x) for x in row) + "]" for row in np.atleast_2d(a)) + "]"


def scene_toml(sys_: System, scheme: str, steps: int, pairing: str | None = None,
               displacement=None, velocity=None, comment: str = "") -> str:
    out = []
    if comment:
        out += [f"# {line}" for line in comment.splitlines()] + [""]
    out += ["[structure]", f"mass = {_matrix(sys_.mass)}", f"stiffness = {_matrix(sys_.stiffness)}", ""]
    spec = sys_.damping_spec
    if spec is not None:
        out.append("[damping]")
        if spec[0] == "rayleigh":
            out.append(f"rayleigh = [{_num(spec[1])}, {_num(spec[2])}]")
        else:
            out.append(f"matrix = {_matrix(sys_.damping)}")
        out.append("")
    out += ["[excitation]", f"frequency = {_num(sys_.omega)}", ""]
    for f in sys_.forces:
        out += ["[[force]]", f"dof = {f.dof}", f"amplitude = {_num(f.amplitude)}", f"harmonic = {f.harmonic}",
                f"phase = {_num(f.phase)}", ""]
    for c in sys_.contacts:
        out += ["[[contact]]", f"dof = {c.dof}", f"direction = {c.direction}", f"gap = {_num(c.gap)}"]
        if c.stiffness is not None:
            out.append(f"stiffness = {_num(c.stiffness)}")
        if c.motion:
            terms = ", ".join(f"{{ amplitude = {_num(m.amplitude)}, harmonic = {m.harmonic}, phase = {_num(m.phase)} }}"
                              for m in c.motion)
            out.append(f"motion = [{terms}]")
        out.append("")
    out += ["[discretization]", f'scheme = "{scheme}"', f"steps = {int(steps)}"]
    if pairing is not None:
        out.append(f'pairing = "{pairing}"')
    out.append("")
    dofs = list(range(sys_.n))
    disp = dofs if displacement is None else list(displacement)
    vel = dofs if velocity is None else list(velocity)
    out += ["[output]", f"displacement = [{', '.join(map(str, disp))}]", f"velocity = [{', '.join(map(str, vel))}]", ""]
    return "\n".join(out)


def system_from_toml(text: str) -> tuple[System, dict]:
    """Parse a scene back (tests of the writer; independent of the engine's parser)."""
    import tomllib

    from marching.model import Contact, Force, Motion

    d = tomllib.loads(text)
    st = d["structure"]
    dmp = d.get("damping", {})
    forces = [Force(f["dof"], f["amplitude"], f.get("harmonic", 1), f.get("phase", 0.0)) for f in d.get("force", [])]
    contacts = [Contact(c["dof"], c["gap"], c.get("direction", 1), c.get("stiffness"),
                        tuple(Motion(m["amplitude"], m["harmonic"], m.get("phase", 0.0)) for m in c.get("motion", [])))
                for c in d.get("contact", [])]
    sys_ = System.build(st["mass"], st["stiffness"], d["excitation"]["frequency"], forces=forces, contacts=contacts,
                        damping=dmp.get("matrix"), rayleigh=dmp.get("rayleigh"))
    return sys_, {"discretization": d["discretization"], "output": d.get("output", {})}
