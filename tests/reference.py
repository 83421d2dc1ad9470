"""Independent references for the tests: exact series of the elliptic-integral periods, and
the driven oscillator's periodic orbit by SciPy.

Nothing here calls the package: the Taylor coefficients come from the hypergeometric series
``K(m) = π/2 Σ [(1/2)_n / n!]² m^n`` with plain ``fractions.Fraction`` arithmetic, the orbit
from ``scipy.integrate.solve_ivp``.
"""

from __future__ import annotations

from fractions import Fraction
from math import factorial


def _k_coefficients(order: int) -> list[Fraction]:
    """``(2/π) K(m) = Σ c_n m^n``, ``c_n = [(2n)! / (4^n n!²)]²``."""
    return [
        Fraction(factorial(2 * n), 4**n * factorial(n) ** 2) ** 2 for n in range(order + 1)
    ]


def _poch(a: Fraction, k: int) -> Fraction:
    out = Fraction(1)
    for i in range(k):
        out *= a + i
    return out


def duffing_period(order: int) -> list[Fraction]:
    """``T/2π`` in ``x = εA²``: ``T = 4K(m)/√(1+x)``, ``m = x/(2(1+x))``.

    ``T/2π = Σ_n c_n (x/2)^n (1+x)^(-n-1/2)``; the binomial series gives each ``x^j``.
    """
    c = _k_coefficients(order)
    out = []
    for j in range(order + 1):
        total = Fraction(0)
        for n in range(j + 1):
            k = j - n
            binom = (-1) ** k * _poch(Fraction(2 * n + 1, 2), k) / factorial(k)
            total += c[n] * Fraction(1, 2**n) * binom
        out.append(total)
    return out


def _mul(a: list[Fraction], b: list[Fraction], order: int) -> list[Fraction]:
    return [sum(a[i] * b[j - i] for i in range(j + 1)) for j in range(order + 1)]


def pendulum_period(order: int) -> list[Fraction]:
    """``T/2π = (2/π) K(sin²(θ₀/2))`` in ``y = θ₀²``.

    ``sin²(θ/2) = Σ_{k≥1} (-1)^(k+1) y^k / (2(2k)!)``.
    """
    m = [Fraction(0)] + [
        Fraction((-1) ** (k + 1), 2 * factorial(2 * k)) for k in range(1, order + 1)
    ]
    c = _k_coefficients(order)
    out = [Fraction(0)] * (order + 1)
    power = [Fraction(1)] + [Fraction(0)] * order
    for n in range(order + 1):
        out = [o + c[n] * p for o, p in zip(out, power, strict=True)]
        power = _mul(power, m, order)
    return out


def reciprocal(series: list[Fraction]) -> list[Fraction]:
    """``1 / Σ a_j y^j`` for ``a_0 = 1``."""
    out = [Fraction(1)]
    for j in range(1, len(series)):
        out.append(-sum(series[a] * out[j - a] for a in range(1, j + 1)))
    return out


def periodic_orbit(eps: float, force: float, omega: float, q0: float,
                   rtol: float = 1e-12, samples: int = 64, damping: float = 0.0,
                   p0: float = 0.0) -> tuple:
    """The periodic orbit of ``q'' + c q' + q + εq³ = f cos ωt`` (``c``: ``damping``, none by
    default) through ``q(0) ≈ q0``, ``q'(0) ≈ p0``: Newton's method on the period map
    ``y(0) ↦ y(2π/ω)`` (SciPy's DOP853 at ``rtol``, the Jacobian from the variational
    equations), then the Fourier coefficients of
    ``q = Σ A_n cos nωt + B_n sin nωt`` from ``samples`` points of one period (arrays indexed
    by n).  SciPy and NumPy only."""
    import numpy as np
    from scipy.integrate import solve_ivp

    period = 2 * np.pi / omega

    def rhs(t, y):
        k = -1 - 3 * eps * y[0] ** 2
        return [y[1], -y[0] - eps * y[0] ** 3 - damping * y[1] + force * np.cos(omega * t),
                y[4], y[5], k * y[2] - damping * y[4], k * y[3] - damping * y[5]]

    def flow(y0, t_eval=None):
        return solve_ivp(rhs, (0, period), [*y0, 1.0, 0.0, 0.0, 1.0], method="DOP853",
                         rtol=rtol, atol=rtol * 1e-3, t_eval=t_eval)

    y0 = np.array([q0, p0])
    for _ in range(30):
        end = flow(y0).y[:, -1]
        step = np.linalg.solve(end[2:].reshape(2, 2) - np.eye(2), y0 - end[:2])
        y0 = y0 + step
        if np.max(np.abs(step)) < 1e-13 * (1 + np.max(np.abs(y0))):
            break
    else:
        raise RuntimeError(f"no periodic orbit near q0 = {q0}")
    q = flow(y0, np.arange(samples) * period / samples).y[0]
    c = np.fft.rfft(q) / samples
    A, B = 2 * c.real, -2 * c.imag
    A[0] /= 2  # the mean
    return A, B
