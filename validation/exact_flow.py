"""Exact-flow periodic orbits of a linear structure with compliant unilateral contacts, free of any
time grid (issue 23's reference; the 1-2 DOF closed forms are in marching/exact.py).

    M x'' + C x' + K x = f(t) - B^T z,   z_i = k_i max(0, B_i x - g_i(t))

with f and g finite sums of harmonics of ω. Between two contact switches the active set S is fixed
and the system is linear with harmonic forcing, solved exactly:
- the particular periodic solution of S by its harmonic response (one solve per harmonic);
- the homogeneous part by the eigen-decomposition of S's 2n×2n state matrix, computed once per
  topology and cached (a topology is visited every period).
Massless DOFs (zero rows of M and C, the massless-boundary reduction) are condensed statically in
each topology (x_b = K_S,bb⁻¹ (f_S,b − K_S,ba x_a)); the state is then (x_a, v_a).
Switches are located by a sign search of every B_i x − g_i(t) on a grid finer than the fastest
mode, then Brent's method to ~1e-15 relative in time. The periodic orbit is found by Newton
shooting on the state at t = 0, with the monodromy as the product of the segments' exponentials.

Command line (the model written by `periodic-contact export SCENE -o DIR`):
    python validation/exact_flow.py DIR [--guess result.json] [-o orbit.json] [--samples K]
"""
from __future__ import annotations

import argparse
import json
import os
import time
from dataclasses import dataclass, field

# Small dense products (n ≲ 200) run fastest on one thread; on a loaded machine a threaded BLAS
# is 10x slower here (measured). Only effective when numpy is not imported yet.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.io import mmread  # noqa: E402
from scipy.linalg import eigh  # noqa: E402
from scipy.optimize import brentq, minimize_scalar  # noqa: E402


def _harmonic_array(terms, H: int) -> np.ndarray:
    """Complex amplitudes F_h (h = 0..H) of Σ a cos(h ω t + φ): value(t) = Re Σ F_h e^{i h ω t}."""
    out = np.zeros(H + 1, dtype=complex)
    for h, a, phi in terms:
        out[h] += a * np.exp(1j * phi)
    return out


@dataclass
class ContactModel:
    """The structure, its compliant contacts and its harmonic loads, in the export's conventions."""

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    B: np.ndarray                 # (m, n) rows of the contact normals
    stiffness: np.ndarray         # (m,) k_i
    G: np.ndarray                 # (m, H+1) gap harmonics: g(t) = Re Σ G_h e^{i h ω t}
    F: np.ndarray                 # (n, H+1) load harmonics
    omega: float
    outputs: dict = field(default_factory=dict)   # key -> (n,) row

    @property
    def n(self) -> int:
        return self.K.shape[0]

    @property
    def m(self) -> int:
        return self.B.shape[0]

    @property
    def H(self) -> int:
        return self.F.shape[1] - 1

    @property
    def period(self) -> float:
        return 2 * np.pi / self.omega

    @classmethod
    def build(cls, M, C, K, B, stiffness, gap_terms, force_terms, omega, outputs=None):
        """gap_terms[i]: list of (h, a, φ) (h = 0 for the mean); force_terms: list of (dof, h, a, φ)."""
        M, K = np.atleast_2d(np.asarray(M, float)), np.atleast_2d(np.asarray(K, float))
        C = np.zeros_like(K) if C is None else np.atleast_2d(np.asarray(C, float))
        B = np.atleast_2d(np.asarray(B, float))
        H = max([h for terms in gap_terms for h, _, _ in terms] + [h for _, h, _, _ in force_terms] + [0])
        G = np.array([_harmonic_array(terms, H) for terms in gap_terms]).reshape(B.shape[0], H + 1)
        F = np.zeros((K.shape[0], H + 1), dtype=complex)
        for d, h, a, phi in force_terms:
            F[d, h] += a * np.exp(1j * phi)
        outs = outputs if outputs is not None else {str(d): np.eye(K.shape[0])[d] for d in range(K.shape[0])}
        return cls(M, C, K, B, np.asarray(stiffness, float), G, F, float(omega), outs)

    @classmethod
    def load(cls, folder: str) -> "ContactModel":
        """The model written by `periodic-contact export SCENE -o folder`."""
        man = json.load(open(os.path.join(folder, "model.json")))
        files = man["files"]
        dense = lambda name: np.asarray(mmread(os.path.join(folder, name)).todense(), dtype=float)  # noqa: E731
        M, K = dense(files["mass"]), dense(files["stiffness"])
        C = dense(files["damping"]) if files.get("damping") else None
        n = man["n"]
        if files.get("contact_rows"):
            B = dense(files["contact_rows"])
        else:
            B = np.zeros((0, n))
        rigid = [i for i, c in enumerate(man["contacts"]) if c["stiffness"] is None]
        if rigid:
            raise ValueError(f"{folder}/model.json: contacts {rigid} are rigid; the exact-flow reference "
                             "takes compliant contacts (give each contact a stiffness in the scene)")
        gaps = [[(0, c["gap_static"], 0.0)] + [(t["harmonic"], t["amplitude"], t["phase"]) for t in c["gap_harmonics"]]
                for c in man["contacts"]]
        forces = [(f["dof"], f["term"]["harmonic"], f["term"]["amplitude"], f["term"]["phase"]) for f in man["forces"]]
        outputs = {}
        for o in man["outputs"]:
            r = np.zeros(n)
            for d, c in o["row"]:
                r[d] += c
            outputs[o["key"]] = r
        return cls.build(M, C, K, B, [c["stiffness"] for c in man["contacts"]], gaps, forces, man["omega"], outputs)


class Topology:
    """One active set S: its condensed state matrix, eigen-decomposition and particular solution."""

    def __init__(self, mdl: ContactModel, active: np.ndarray, massive: np.ndarray):
        self.active = active.copy()
        a = massive
        b = np.setdiff1d(np.arange(mdl.n), a)
        kS = mdl.stiffness * active
        KS = mdl.K + mdl.B.T @ (kS[:, None] * mdl.B)
        FS = mdl.F + mdl.B.T @ (kS[:, None] * mdl.G)
        na, n = a.size, mdl.n
        # x = P x_a + Re Σ Xq_h e^{ihωt}: static condensation of the massless DOFs.
        P = np.zeros((n, na))
        P[a, np.arange(na)] = 1.0
        Xq = np.zeros((n, mdl.H + 1), dtype=complex)
        if b.size:
            Kbb = KS[np.ix_(b, b)]
            P[b] = -np.linalg.solve(Kbb, KS[np.ix_(b, a)])
            Xq[b] = np.linalg.solve(Kbb, FS[b])
        Kt = KS[np.ix_(a, a)] + KS[np.ix_(a, b)] @ P[b] if b.size else KS
        Ft = FS[a] - KS[np.ix_(a, b)] @ Xq[b] if b.size else FS
        Ma, Ca = mdl.M[np.ix_(a, a)], mdl.C[np.ix_(a, a)]
        Minv = np.linalg.inv(Ma)
        A = np.block([[np.zeros((na, na)), np.eye(na)], [-Minv @ Kt, -Minv @ Ca]])
        self.A = A
        # Eigen-decomposition in the topology's modal coordinates u = (q, q'/ω_j), x = Φ q with
        # Φᵀ M Φ = I, Φᵀ K_S Φ = diag(ω²): there the state matrix is diag(ω)-skew plus the
        # (small) damping, its eigenvectors nearly orthonormal. In [x; v] directly the scales 1 and
        # ω_max mix and the eigenvectors' condition (1.7e7 on the blade, ω_max = 8e6 rad/s) cost
        # about 9 digits of V⁻¹.
        w2, Phi = eigh(Kt, Ma)
        w = np.sqrt(np.maximum(w2, 0.0))
        if np.any(w <= 0):
            raise ValueError("the condensed stiffness of a topology is singular (a rigid-body mode)")
        Cm = (Phi.T @ Ca @ Phi) * (w[None, :] / w[:, None])
        Z = np.zeros((na, na))
        lam, Vu = np.linalg.eig(np.block([[Z, np.diag(w)], [-np.diag(w), -Cm]]))
        Tm = np.block([[Phi, Z], [Z, Phi * w[None, :]]])
        PhiTM = Phi.T @ Ma
        Tinv = np.block([[PhiTM, Z], [Z, PhiTM / w[:, None]]])
        self.lam, self.V = lam, Tm @ Vu
        self.Vinv = np.linalg.solve(Vu, Tinv)
        s = 1j * mdl.omega * np.arange(mdl.H + 1)
        Xa = np.array([np.linalg.solve(Kt + s[h] * Ca + s[h] ** 2 * Ma, Ft[:, h]) for h in range(mdl.H + 1)]).T
        self.s = s
        self.Yp = np.vstack([Xa, Xa * s[None, :]])          # (2na, H+1) particular state harmonics
        self.P, self.Xq = P, Xq
        BP = mdl.B @ P
        # Switching functions B x − g = Re[Sh e^{iht}] + Re[W e^{Λτ} c]
        self.Sh = BP @ Xa + mdl.B @ Xq - mdl.G
        self.W = BP @ self.V[:na]
        self.na = na

    def particular(self, t):
        """Particular state y_p(t) (2na, len(t))."""
        e = np.exp(np.outer(self.s, np.atleast_1d(t)))
        return np.real(self.Yp @ e)

    def coefficients(self, t0, y0):
        return self.Vinv @ (y0 - self.particular(t0)[:, 0])

    def state(self, t, t0, c):
        t = np.atleast_1d(t)
        return self.particular(t) + np.real(self.V @ (np.exp(np.outer(self.lam, t - t0)) * c[:, None]))

    def switching(self, t, t0, c, rows=slice(None)):
        """B_i x(t) − g_i(t) for the rows asked, (rows, len(t))."""
        t = np.atleast_1d(t)
        e = np.exp(np.outer(self.s, t))
        return np.real(self.Sh[rows] @ e) + np.real(self.W[rows] @ (np.exp(np.outer(self.lam, t - t0)) * c[:, None]))

    def transition(self, tau):
        """e^{A τ} (real), the segment's state transition."""
        return np.real(self.V @ (np.exp(self.lam * tau)[:, None] * self.Vinv))

    def full_displacement(self, t, y):
        """x (n, len(t)) from the state y (2na, len(t))."""
        e = np.exp(np.outer(self.s, np.atleast_1d(t)))
        return self.P @ y[: self.na] + np.real(self.Xq @ e)


@dataclass
class Segment:
    t0: float
    t1: float
    topo: Topology
    c: np.ndarray


class ExactFlow:
    """The exact flows of a ContactModel; topologies cached by active set."""

    def __init__(self, mdl: ContactModel, search_points: int = 8):
        self.mdl = mdl
        M = mdl.M
        massive = np.where(np.abs(np.diag(M)) > 0)[0]
        massless = np.setdiff1d(np.arange(mdl.n), massive)
        if massless.size and (np.any(M[massless] != 0) or np.any(mdl.C[massless] != 0) or np.any(mdl.C[:, massless] != 0)):
            raise ValueError("massless DOFs must have zero rows and columns in M and C (static condensation)")
        self.massive = massive
        self.cache: dict[bytes, Topology] = {}
        self.search_points = search_points
        self.stats = {"topologies": 0, "segments": 0}

    def topology(self, active: np.ndarray) -> Topology:
        key = np.packbits(active).tobytes()
        t = self.cache.get(key)
        if t is None:
            t = Topology(self.mdl, active, self.massive)
            self.cache[key] = t
            self.stats["topologies"] += 1
        return t

    def _grid_step(self, topo: Topology) -> float:
        # `search_points` samples per oscillation of the fastest mode or harmonic, and at least
        # 512 per period: a sign change between samples is then a single crossing unless two
        # switches fall within ~1/8 of the fastest period (grazing), which the search may miss
        fast = np.max(np.abs(topo.lam)) if topo.lam.size else 0.0
        rate = max(fast, self.mdl.H * self.mdl.omega, self.mdl.omega)
        return min(self.mdl.period / 512, 2 * np.pi / rate / self.search_points)

    def run(self, t0: float, y0: np.ndarray, t_end: float, active: np.ndarray | None = None,
            keep: bool = False):
        """Flows from (t0, y0) to t_end: (y(t_end), monodromy ∂y(t_end)/∂y0, segments if keep).

        The monodromy is the product of the segments' e^{A_S τ} alone: with compliant contacts the
        vector field is continuous across a switch (the force k_i (B_i x − g_i) is zero there), so
        the saltation matrix I + (f⁺ − f⁻) ∇sᵀ / (∇s·f⁻) is the identity and no jump is needed.
        """
        mdl = self.mdl
        if active is None:
            active = self._active_at(t0, y0)
        J = np.eye(y0.size)
        segs = []
        t, y = t0, np.asarray(y0, float).copy()
        while t < t_end:
            topo = self.topology(active)
            c = topo.coefficients(t, y)
            t_sw, which = self._next_switch(topo, t, c, active, t_end)
            y = np.real(topo.state([t_sw], t, c)[:, 0])
            J = topo.transition(t_sw - t) @ J
            if keep:
                segs.append(Segment(t, t_sw, topo, c))
            self.stats["segments"] += 1
            t = t_sw
            if which is not None:
                active = active.copy()
                active[which] = ~active[which]
        return y, J, segs, active

    def _active_at(self, t, y):
        # the active set of the state y (contacts with B x − g > 0), through the condensation of
        # the inactive topology (for massless DOFs the answer is iterated to a fixed point)
        active = np.zeros(self.mdl.m, dtype=bool)
        for _ in range(self.mdl.m + 2):
            topo = self.topology(active)
            s = topo.switching([t], t, topo.coefficients(t, y))[:, 0]
            new = s > 0
            if np.array_equal(new, active):
                break
            active = new
        return active

    def _next_switch(self, topo: Topology, t0, c, active, t_end):
        """Earliest t in (t0, t_end] where some B_i x − g_i changes sign against the active set."""
        dt = self._grid_step(topo)
        expect = np.where(active, 1.0, -1.0)[:, None]
        chunk = 256
        start = t0
        while start < t_end:
            stop = min(t_end, start + chunk * dt)
            npts = max(2, int(np.ceil((stop - start) / dt)) + 1)
            ts = np.linspace(start, stop, npts)
            sw = topo.switching(ts, t0, c)
            bad = (sw * expect) < 0
            bad[:, 0] = False          # the just-switched contact sits at 0 at t0
            if bad.any():
                j = np.argmax(bad, axis=1)
                rows = np.where(bad.any(axis=1))[0]
                best_t, best_i = np.inf, None
                jmin = j[rows].min()
                for i in rows[j[rows] <= jmin]:
                    f = lambda tt, i=i: topo.switching([tt], t0, c, rows=[i])[0, 0]  # noqa: E731
                    a, b = ts[j[i] - 1], ts[j[i]]
                    fa, fb = f(a), f(b)
                    if fa * fb > 0:           # the just-switched contact grazes back at once
                        r = a
                    else:
                        r = brentq(f, a, b, xtol=1e-15 * max(abs(b), self.mdl.period), rtol=4 * np.finfo(float).eps, maxiter=200)
                    if r < best_t:
                        best_t, best_i = r, i
                return best_t, [best_i]
            start = stop
        return t_end, None

    def periodic_orbit(self, y0, tol=1e-13, max_iter=30, verbose=False):
        """Newton shooting on y(0) = y(T); returns the Orbit."""
        T = self.mdl.period
        y = np.asarray(y0, float).copy()
        na = self.massive.size
        hist = []
        for it in range(max_iter):
            yT, J, _, _ = self.run(0.0, y, T)
            R = yT - y
            scale = np.concatenate([np.full(na, max(np.max(np.abs(y[:na])), 1e-300)),
                                    np.full(na, max(np.max(np.abs(y[na:])), 1e-300))])
            err = np.max(np.abs(R) / scale)
            hist.append(err)
            if verbose:
                print(f"  Newton {it}: |y(T) - y(0)| = {err:.3e} (relative), topologies {self.stats['topologies']}")
            # converged, or at the round-off floor (1-3e-13 on 100 DOFs): Newton no longer halves it
            if err < tol or (len(hist) > 1 and err < 1e3 * tol and err > 0.5 * hist[-2]):
                break
            dy = np.linalg.solve(J - np.eye(y.size), -R)
            # damped step: halve while the residual grows (the flow is piecewise smooth)
            lam = 1.0
            for _ in range(20 if err > 1e-8 else 1):
                yn = y + lam * dy
                Rn = self.run(0.0, yn, T)[0] - yn
                if np.max(np.abs(Rn) / scale) < err or lam < 1e-3:
                    break
                lam /= 2
            y = yn
        else:
            raise RuntimeError(f"exact-flow Newton did not converge: residuals {hist}")
        yT, J, segs, _ = self.run(0.0, y, T, keep=True)
        return Orbit(self, y, segs, J, hist)

    def guess_from_forces(self, times, forces):
        """State at t = 0 of the linear response to f(t) − Bᵀ z(t), z sampled at `times` (m, k):
        a grid answer's contact forces give a whole-state guess."""
        mdl = self.mdl
        z = np.asarray(forces, float).reshape(mdl.m, -1)
        k = z.shape[1]
        Z = np.fft.rfft(z, axis=1) / k
        Z[:, 1:] *= 2
        if k % 2 == 0:
            Z[:, -1] /= 2
        nh = Z.shape[1]
        x0 = np.zeros(mdl.n)
        v0 = np.zeros(mdl.n)
        for h in range(nh):
            Fh = (mdl.F[:, h] if h <= mdl.H else 0) - mdl.B.T @ Z[:, h]
            s = 1j * h * mdl.omega
            X = np.linalg.solve(mdl.K + s * mdl.C + s * s * mdl.M, Fh)
            x0 += np.real(X)
            v0 += np.real(s * X)
        a = self.massive
        return np.concatenate([x0[a], v0[a]])

    def guess_by_marching(self, periods: int = 50):
        """March the exact flows from the contact-free response for some periods (damped systems)."""
        mdl = self.mdl
        a = self.massive
        X = np.linalg.solve(mdl.K + 1j * mdl.omega * mdl.C - mdl.omega**2 * mdl.M, mdl.F[:, 1]) if mdl.H >= 1 else np.zeros(mdl.n)
        y = np.concatenate([np.real(X)[a], np.real(1j * mdl.omega * X)[a]])
        for _ in range(periods):
            y = self.run(0.0, y, mdl.period)[0]
        return y


class Orbit:
    """The periodic orbit: state at 0, segments over [0, T], contact phases."""

    def __init__(self, flow: ExactFlow, y0, segments, monodromy, history):
        self.flow, self.y0, self.segments, self.monodromy, self.history = flow, y0, segments, monodromy, history

    @property
    def T(self):
        return self.flow.mdl.period

    def displacement(self, t):
        """x (n, len(t)) at any instants (taken modulo T)."""
        t = np.mod(np.atleast_1d(np.asarray(t, float)), self.T)
        x = np.zeros((self.flow.mdl.n, t.size))
        starts = np.array([s.t0 for s in self.segments])
        idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.segments) - 1)
        for i in np.unique(idx):
            sel = idx == i
            s = self.segments[i]
            y = s.topo.state(t[sel], s.t0, s.c)
            x[:, sel] = s.topo.full_displacement(t[sel], y)
        return x

    def output(self, key, t):
        return self.flow.mdl.outputs[key] @ self.displacement(t)

    def peak_to_peak(self, key, samples=4096):
        """Exact peak-to-peak of an output: extrema on a fine grid refined by Brent."""
        T = self.T
        ts = np.linspace(0, T, samples, endpoint=False)
        x = self.output(key, ts)
        f = lambda t: self.output(key, [t])[0]  # noqa: E731
        ext = []
        for j, sign in ((np.argmax(x), -1.0), (np.argmin(x), 1.0)):
            r = minimize_scalar(lambda t: sign * f(t), bounds=(ts[j] - T / samples, ts[j] + T / samples), method="bounded",
                                options={"xatol": 1e-14 * T})
            ext.append(max(f(r.x), x[j]) if sign < 0 else min(f(r.x), x[j]))
        return ext[0] - ext[1]

    def switches(self):
        """[(time, contact, 'on' | 'off')] over one period."""
        out = []
        for a, b in zip(self.segments[:-1], self.segments[1:]):
            for i in np.where(a.topo.active != b.topo.active)[0]:
                out.append((b.t0, int(i), "on" if b.topo.active[i] else "off"))
        return out


def compare_with_grid(orbit: Orbit, result: dict):
    """Errors of a grid answer (the CLI's JSON) against the orbit, relative to each output's exact
    peak-to-peak: max over the grid instants, and of the peak-to-peak taken on the same instants;
    `relative_to_largest`: the largest absolute error over the largest output's peak-to-peak, the
    measure of the CLI's own error estimate (so the two can be set side by side)."""
    t = np.asarray(result["time"], float)
    worst = {"max_over_orbit": 0.0, "peak_to_peak": 0.0, "key_max": None}
    largest_error, largest_ptp = 0.0, 0.0
    for key, xs in result["displacement"].items():
        if key not in orbit.flow.mdl.outputs:
            continue
        xe = orbit.output(key, t)
        ptp = orbit.peak_to_peak(key)
        error = np.max(np.abs(np.asarray(xs) - xe))
        largest_error, largest_ptp = max(largest_error, error), max(largest_ptp, ptp)
        e_max = error / ptp
        e_ptp = abs(np.ptp(xs) - np.ptp(xe)) / ptp
        if e_max > worst["max_over_orbit"]:
            worst.update(max_over_orbit=e_max, key_max=key)
        worst["peak_to_peak"] = max(worst["peak_to_peak"], e_ptp)
    worst["relative_to_largest"] = largest_error / largest_ptp if largest_ptp > 0 else 0.0
    return worst


def solve_exported(folder: str, guess: dict | None = None, verbose=False):
    """The exact orbit of an exported model, from a CLI answer's contact forces when given."""
    mdl = ContactModel.load(folder)
    flow = ExactFlow(mdl)
    if guess is not None:
        z = np.array([c["force"] for c in guess["contacts"]])
        y0 = flow.guess_from_forces(guess["time"], z)
    else:
        y0 = flow.guess_by_marching()
    return flow.periodic_orbit(y0, verbose=verbose)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", help="the folder written by `periodic-contact export`")
    ap.add_argument("--guess", help="a CLI answer (JSON of `periodic-contact solve`) as the initial guess")
    ap.add_argument("-o", "--output", help="write the orbit (samples, peak-to-peak, switches) as JSON")
    ap.add_argument("--samples", type=int, default=1024, help="instants per period in the output")
    args = ap.parse_args(argv)
    guess = json.load(open(args.guess)) if args.guess else None
    t0 = time.perf_counter()
    orbit = solve_exported(args.folder, guess, verbose=True)
    el = time.perf_counter() - t0
    fl = orbit.flow
    print(f"orbit: {len(orbit.switches())} switches, {fl.stats['topologies']} topologies, {el:.2f} s")
    ts = np.arange(args.samples) * orbit.T / args.samples
    out = {"period": orbit.T, "time": ts.tolist(), "displacement": {}, "peak_to_peak": {},
           "switches": orbit.switches(), "newton": orbit.history, "seconds": el}
    for key in fl.mdl.outputs:
        out["displacement"][key] = orbit.output(key, ts).tolist()
        out["peak_to_peak"][key] = orbit.peak_to_peak(key)
        print(f"  output {key}: peak-to-peak {out['peak_to_peak'][key]:.10e}")
    if guess is not None:
        e = compare_with_grid(orbit, guess)
        print(f"guess ({guess.get('scheme')}, k = {guess.get('steps')}): error {e['max_over_orbit']:.3e} max over the "
              f"orbit, {e['peak_to_peak']:.3e} of the peak-to-peak")
    if args.output:
        json.dump(out, open(args.output, "w"))


if __name__ == "__main__":
    main()
