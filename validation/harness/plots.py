"""One figure per case: the time-marching trajectory (transient light, last period bold), the
periodic response of the engine (CLI samples, FMU communication points), the discrete marcher,
and the contact force over the last period."""
from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .report import FIGURES  # noqa: E402

COLORS = plt.rcParams["axes.prop_cycle"].by_key()["color"]


def plot_case(case, ref, discrete=None, engine=None, fmu=None, exact=None, path=None) -> str:
    """ref: continuous MarchResult; discrete: MarchResult of the discrete marcher; engine:
    EngineResult (CLI); fmu: FmuRun; exact: optional (t, x (n, N)) continuous exact solution."""
    sys_ = case.system
    T = sys_.period
    dofs = case.output_dofs
    fig, axs = plt.subplots(2, 2, figsize=(13, 8.5))
    ax_tr, ax_x, ax_v, ax_f = axs[0, 0], axs[0, 1], axs[1, 0], axs[1, 1]

    # transient: whole run, light; last period bold
    t_last0 = (ref.periods - 1) * T
    for c, d in enumerate(dofs):
        col = COLORS[c % len(COLORS)]
        ax_tr.plot(ref.hist_t / T, ref.hist_x[d], color=col, lw=0.6, alpha=0.35)
        ax_tr.plot((t_last0 + ref.t) / T, ref.x[d], color=col, lw=1.8, label=f"x[{d}] last period")
    ax_tr.set_xlabel("t / T")
    ax_tr.set_title(f"{ref.method}: transient from rest ({ref.periods} periods, {ref.cpu_time:.2f} s CPU)")
    ax_tr.legend(fontsize=7, loc="upper right")

    # last period: displacement and velocity
    ph = ref.t / T
    for ax, key, lab in ((ax_x, "x", "displacement"), (ax_v, "v", "velocity")):
        for c, d in enumerate(dofs):
            col = COLORS[c % len(COLORS)]
            ax.plot(ph, getattr(ref, key)[d], color=col, lw=2.0, label=f"{lab}[{d}] marcher")
            if discrete is not None:
                ax.plot(discrete.t / T, getattr(discrete, key)[d], color="k", lw=0.7, ls="--",
                        label="discrete marcher" if c == 0 else None)
            if engine is not None:
                vals = (engine.x if key == "x" else engine.v).get(d)
                if vals is not None:
                    stride = max(1, engine.steps // 128)
                    ax.plot(engine.t[::stride] / T, vals[::stride], "o", ms=3, mfc="none", color=col,
                            label=f"CLI {engine.raw.get('scheme')} k={engine.steps}" if c == 0 else None)
            if fmu is not None and f"{key}{d}" in fmu.values:
                sel = fmu.time <= T * (1 + 1e-12)
                stride = max(1, int(sel.sum()) // 96)
                ax.plot(fmu.time[sel][::stride] / T, fmu.values[f"{key}{d}"][sel][::stride], "x", ms=4, color=col,
                        label="FMU (fmpy)" if c == 0 else None)
        ax.set_xlabel("phase t / T")
        ax.set_title(f"last period: {lab}")
        ax.legend(fontsize=7, loc="best")
    for i, cont in enumerate(sys_.contacts):  # obstacle position in DOF coordinates: x[dof] = s gap(t)
        ax_x.plot(ph, cont.direction * sys_.gaps(ref.t)[i], color="0.5", lw=1.0, ls="-.",
                  label="obstacle (s·gap)" if i == 0 else None)
    if sys_.contacts:
        ax_x.legend(fontsize=7, loc="best")
    if exact is not None:
        te, xe = exact
        for c, d in enumerate(dofs):
            ax_x.plot(te / T, xe[d], color="w", lw=0.6, ls=":")

    # contact force
    if sys_.m:
        for i, cont in enumerate(sys_.contacts):
            col = COLORS[(i + 3) % len(COLORS)]
            ax_f.plot(ph, ref.force[i], color=col, lw=2.0, label=f"contact {i} (dof {cont.dof}) marcher")
            for (t_imp, ii, P) in ref.impacts:
                if ii == i:
                    ax_f.annotate(f"impulse {P:.4g}", (t_imp / T, 0), xytext=(t_imp / T, 0.5 * max(1e-12, ref.force.max())),
                                  arrowprops=dict(arrowstyle="->", color=col), fontsize=7, color=col, ha="center")
            if discrete is not None:
                ax_f.step(discrete.t / T, discrete.force[i], where="post", color="k", lw=0.7, ls="--",
                          label="discrete marcher" if i == 0 else None)
            if engine is not None and i < engine.force.shape[0]:
                ax_f.step(engine.t / T, engine.force[i], where="post", color=col, lw=0.9, alpha=0.8,
                          label=f"CLI force (impulse {engine.impulse[i]:.4g})")
        rigid = any(c.rigid for c in sys_.contacts)
        ax_f.set_title("contact force, last period" + (" (rigid)" if rigid else ""))
        imp = ", ".join(f"{v:.5g}" for v in ref.impulse)
        txt = f"marcher impulse/period: {imp}"
        fmax = float(np.max(ref.force)) if ref.force.size else 0.0
        if rigid:
            # discrete impact samples are impulse/h: spikes of O(1/h), clipped to keep the smooth
            # sticking force readable
            others = [float(np.max(d.force)) for d in (discrete,) if d is not None and d.force.size]
            top = 1.5 * fmax if fmax > 0 else (max(others) if others else 1.0)
            ax_f.set_ylim(-0.05 * top, top)
            txt += "\nimpacts: arrows (marcher); discrete impact samples = impulse/h, clipped"
        else:
            ax_f.set_ylim(bottom=-0.05 * max(fmax, 1e-12))
        ax_f.text(0.02, 0.95, txt, transform=ax_f.transAxes, fontsize=8, va="top")
        ax_f.legend(fontsize=7, loc="upper right")
    else:
        ax_f.text(0.5, 0.5, "no contact", ha="center", va="center", transform=ax_f.transAxes)
    ax_f.set_xlabel("phase t / T")
    fig.suptitle(f"{case.name}: {case.title}   (ω = {sys_.omega}, T = {T:.4f})")
    fig.tight_layout()
    path = path or os.path.join(FIGURES, f"{case.name}.png")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
