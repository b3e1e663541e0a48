"""A frequency ramp through the C API (issue 24): one problem handle solved at N+1 equally spaced
frequencies from W0 to W1; prints each jump (pc_result_jump) and the last amplitude of
displacement 0 (half its peak-to-peak over the k instants) with the CPU time.

    python3 validation/demo/capi_ramp.py target/release/libperiodic_contact.so SCENE.toml W0 W1 N [-v]

-v prints every step (frequency, amplitude, CPU so far) as it is solved.

A scene without [output] gets displacement = [0, 1]. The README's follow figures ("Branches",
the FMU section) come from this script.
"""
from __future__ import annotations

import ctypes as c
import sys
import time


def main(lib_path: str, scene: str, w0: float, w1: float, n: int, verbose: bool = False) -> int:
    lib = c.CDLL(lib_path)
    lib.pc_problem_from_scene_text.restype = c.c_void_p
    lib.pc_problem_from_scene_text.argtypes = [c.c_char_p]
    lib.pc_problem_set_frequency.argtypes = [c.c_void_p, c.c_double]
    lib.pc_problem_solve.restype = c.c_void_p
    lib.pc_problem_solve.argtypes = [c.c_void_p]
    lib.pc_result_jump.argtypes = [c.c_void_p] + [c.c_void_p] * 5
    lib.pc_result_steps.argtypes = [c.c_void_p]
    lib.pc_result_steps.restype = c.c_size_t
    lib.pc_result_displacement.argtypes = [c.c_void_p, c.c_size_t, c.c_void_p, c.c_size_t]
    lib.pc_result_free.argtypes = [c.c_void_p]
    lib.pc_problem_free.argtypes = [c.c_void_p]
    with open(scene) as fh:
        text = fh.read()
    if "[output]" not in text:
        text += "\n[output]\ndisplacement = [0, 1]\n"
    p = lib.pc_problem_from_scene_text(text.encode())
    if not p:
        print(f"{scene}: not a scene the C API takes", file=sys.stderr)
        return 2
    t0 = time.process_time()
    amplitude, w = 0.0, w0
    for i in range(n + 1):
        w = w0 + (w1 - w0) * i / n
        lib.pc_problem_set_frequency(p, w)
        r = lib.pc_problem_solve(p)
        if not r:
            print(f"solve failed at {w}", file=sys.stderr)
            return 1
        jumped, fold, before, after, jumps = c.c_int(), c.c_double(), c.c_double(), c.c_double(), c.c_size_t()
        lib.pc_result_jump(r, c.byref(jumped), c.byref(fold), c.byref(before), c.byref(after), c.byref(jumps))
        k = lib.pc_result_steps(r)
        x = (c.c_double * k)()
        lib.pc_result_displacement(r, 0, x, k)
        amplitude = (max(x) - min(x)) / 2
        if jumped.value:
            print(f"jump at step {i} w={w:.7f}: fold {fold.value:.7f}, amplitude {before.value:.4f} -> {after.value:.4f}", flush=True)
        if verbose:
            print(f"step {i} w={w:.7f} amplitude_0 {amplitude:.6e} cpu {time.process_time() - t0:.1f} s", flush=True)
        lib.pc_result_free(r)
    lib.pc_problem_free(p)
    print(f"end w={w:.5f} amplitude_0 {amplitude:.6f}; cpu {time.process_time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), sys.argv[6:] == ["-v"]))
