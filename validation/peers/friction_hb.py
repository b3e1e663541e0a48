"""A harmonic-balance peer for one Coulomb friction contact (rigid, or a Jenkins element): the
alternating frequency–time scheme (AFT; Cameron & Griffin, J. Appl. Mech. 56 (1989) 149) with the
dynamic Lagrangian frequency–time friction law (DLFT; Nacivet, Pierre, Thouverez & Jézéquel,
J. Sound Vib. 265 (2003) 201–219), written from the papers for this comparison.

    M x'' + C x' + K x = F cos Ωt − e_d λ(t),      x(t) = Re Σ_{h=0..H} X_h e^{i h Ω t}

Condensation on the slider coordinate w (as in Nacivet et al.): per harmonic X_h = H_h (F_h − e_d Λ_h),
H_h = (K − (hΩ)² M + i hΩ C)⁻¹. The slider is x_d for rigid Coulomb, or the massless end of the
tangential spring k_t of a Jenkins element (λ = k_t (x_d − w)), so

    W_h = W⁰_h − r_h Λ_h,    W⁰_h = e_dᵀ H_h F_h,    r_h = (H_h)_dd (+ 1/k_t).

The unknowns are the 2H+1 real coefficients of W. The linear part's force Λ_X,h = (W⁰_h − W_h)/r_h
and the DLFT contact force Λ = Λ_X + ε (W − Y), where Y is the slider's "contact" displacement
given by the Coulomb law in the time domain (their stick prediction and slip correction, written
with Y): on N samples,

    stick prediction λ_p(t_n) = λ_X(t_n) + ε (w(t_n) − y(t_{n−1}));
    |λ_p| ≤ μN: stick, λ = λ_p, y(t_n) = y(t_{n−1});
    else slip, λ = μN sign(λ_p), y(t_n) = w(t_n) − (λ − λ_X(t_n))/ε,

looped twice over the period (the second pass starts from the first's end: periodic). The
residual is W − Y (displacement units); at a root Λ = Λ_X and the law holds on the samples.
Solved by scipy's fsolve (MINPACK hybrd) with the analytic DLFT Jacobian (y is piecewise linear in
W: a slip sample follows w and λ_X, a stuck one repeats the last slip), seeded by the stuck (linear)
response or a smaller H's root. The displacement harmonics then follow from Λ.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.optimize import fsolve  # noqa: E402


@dataclass
class HBSolution:
    X: np.ndarray           # (H+1, n) complex displacement harmonics
    omega: float
    H: int
    N: int
    residual: float         # max |W − Y|, relative to max |W|
    evaluations: int
    converged: bool
    W: np.ndarray | None = None   # the slider harmonics (a seed for a larger H)

    def displacement(self, times) -> np.ndarray:
        t = np.asarray(times, dtype=float)
        e = np.exp(1j * self.omega * np.outer(t, np.arange(self.H + 1)))
        return (e @ self.X).real

    def amplitude(self, samples: int = 8192) -> np.ndarray:
        x = self.displacement(np.arange(samples) * 2 * np.pi / self.omega / samples)
        return 0.5 * (x.max(axis=0) - x.min(axis=0))


def _to_complex(z: np.ndarray, H: int) -> np.ndarray:
    c = np.zeros(H + 1, dtype=complex)
    c[0] = z[0]
    c[1:] = z[1::2] + 1j * z[2::2]
    return c


def _to_real(c: np.ndarray) -> np.ndarray:
    z = np.zeros(2 * len(c) - 1)
    z[0] = c[0].real
    z[1::2] = c[1:].real
    z[2::2] = c[1:].imag
    return z


def _samples(c: np.ndarray, N: int) -> np.ndarray:
    """w(t_n) = Re Σ c_h e^{2πi h n/N}, n < N (numpy's irfft scaled; needs H < N/2)."""
    spec = np.zeros(N // 2 + 1, dtype=complex)
    spec[: len(c)] = c * (N / 2)
    spec[0] = c[0] * N
    return np.fft.irfft(spec, N)


def _harmonics(w: np.ndarray, H: int) -> np.ndarray:
    spec = np.fft.rfft(w)
    c = spec[: H + 1] * (2 / len(w))
    c[0] = spec[0] / len(w)
    return c


def _dlft_contact(w, lam_x, eps, slip):
    """The DLFT time loop (Nacivet et al. 2003, in the contact displacement y): y(t_n), and for
    the Jacobian the sample each y(t_n) was last set at (a slip sample; −1: stuck all period)."""
    N = len(w)
    w, lam_x = w.tolist(), lam_x.tolist()
    y = [0.0] * N
    source = [-1] * N
    prev, last = w[-1], -1      # first pass from "stuck where the slider is"
    for _ in range(2):
        for n in range(N):
            lp = lam_x[n] + eps * (w[n] - prev)
            if lp > slip:
                prev, last = w[n] - (slip - lam_x[n]) / eps, n
            elif lp < -slip:
                prev, last = w[n] - (-slip - lam_x[n]) / eps, n
            y[n] = prev
            source[n] = last
    return np.array(y), np.array(source)


# ε = EPS_FACTOR/|r_1|: 10 is where hybrd converged most often on the chain at Ω = 0.4, 0.8, 1.85
# (factors 1 and 0.1 stalled more at H ≥ 15; tried by hand before the runs of the README).
EPS_FACTOR = 10.0


def solve(M, C, K, F, omega: float, dof: int, slip_force: float, kt: float | None, H: int,
          N: int | None = None, eps: float | None = None, guess: np.ndarray | None = None, xtol: float = 1e-12,
          analytic: bool = True):
    """HB at H harmonics, N time samples (default the power of two ≥ 16(H+1)); `guess`: the slider
    harmonics W (complex, length ≥ 1) of a previous solve, e.g. at fewer harmonics; `analytic`:
    the DLFT Jacobian (piecewise linear in W), else hybrd's finite differences."""
    n = len(M)
    N = N or int(2 ** np.ceil(np.log2(16 * (H + 1))))
    if N < 2 * H + 2:
        raise ValueError(f"N = {N} samples cannot carry H = {H} harmonics (need N ≥ 2H+2)")
    Hs = [np.linalg.inv(K - (h * omega) ** 2 * M + 1j * h * omega * C) for h in range(H + 1)]
    Fh = np.zeros((H + 1, n), dtype=complex)
    Fh[1] = F
    r = np.array([Hh[dof, dof] + (1.0 / kt if kt else 0.0) for Hh in Hs])
    w0 = np.array([Hs[h][dof] @ Fh[h] for h in range(H + 1)])
    # ε: a multiple of the contact's dynamic stiffness at Ω. It changes the convergence, and at
    # finite H the root too (the sampled law holds only through H harmonics).
    eps = eps or EPS_FACTOR / abs(r[1])
    evals = [0]

    # Real-coefficient operators: samples of w and λ_X from z = [W0, Re W1, Im W1, …], and the
    # harmonics of y back to z (for the analytic Jacobian).
    theta = 2 * np.pi * np.arange(N) / N
    E = np.zeros((N, 2 * H + 1))
    L = np.zeros((N, 2 * H + 1))
    Fm = np.zeros((2 * H + 1, N))
    E[:, 0], L[:, 0], Fm[0] = 1.0, (-1.0 / r[0]).real, 1.0 / N
    for h in range(1, H + 1):
        e = np.exp(1j * h * theta)
        E[:, 2 * h - 1], E[:, 2 * h] = e.real, -e.imag
        L[:, 2 * h - 1], L[:, 2 * h] = (-e / r[h]).real, (-1j * e / r[h]).real
        Fm[2 * h - 1], Fm[2 * h] = 2 / N * e.real, -2 / N * e.imag
    last = {}

    def residual(z):
        evals[0] += 1
        W = _to_complex(z, H)
        y, source = _dlft_contact(_samples(W, N), _samples((w0 - W) / r, N), eps, slip_force)
        last["source"] = source
        return _to_real(W - _harmonics(y, H))

    def jacobian(z):
        # y(t_n) = w(t_m) − (±μN − λ_X(t_m))/ε with m the last slip sample: dy_n = E_m + L_m/ε;
        # stuck all period: y = w(t_{N−1}).
        residual(z)
        src = last["source"]
        rows = np.where(src[:, None] >= 0, E[np.maximum(src, 0)] + L[np.maximum(src, 0)] / eps, E[N - 1])
        return np.eye(2 * H + 1) - Fm @ rows

    W = np.zeros(H + 1, dtype=complex)
    if guess is None:
        W[:] = w0 if kt else 0.0      # stuck: rigid Coulomb holds the slider at 0, Jenkins at w0
    else:
        m = min(len(guess), H + 1)
        W[:m] = guess[:m]
    z, info, ier, msg = fsolve(residual, _to_real(W), fprime=jacobian if analytic else None, xtol=xtol, full_output=True)
    W = _to_complex(z, H)
    res = np.abs(residual(z)).max() / max(np.abs(z).max(), 1e-300)
    lam = (w0 - W) / r
    X = np.array([Hs[h] @ (Fh[h] - np.eye(n)[dof] * lam[h]) for h in range(H + 1)])
    # Converged: the sampled law holds through H harmonics (hybrd may end with 'no progress' on
    # a root it already reached, so its flag alone is not the test).
    return HBSolution(X, omega, H, N, res, evals[0], bool(res < 1e-10), W)
