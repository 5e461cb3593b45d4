"""Special functions for the numba kernels: E1, the Yang–Persson K(s0), erfinv.

All kernels are ``@njit(cache=True)`` and compile on first use, never at import.

- :func:`e1` — exponential integral E1(x): power series for x <= 1, Chebyshev fits of
  x e^x E1(x) on octaves up to 64, Lentz continued fraction above; relative error <= 1e-15
  against mpmath on 1e-14 <= x <= 700. Both polynomials are evaluated by Estrin's scheme
  (independent pairs combined with t², t⁴, t⁸, t¹⁶: a dependency chain of ~5 multiply-adds
  instead of Horner's or Clenshaw's 18), the fits in the monomial basis of t (converted
  exactly from the Chebyshev coefficients): 35 → 20 ns a call for x <= 1, 64 → 25 ns on the
  octaves, the same <= 4.4e-16 against mpmath. E1 is the costliest step of a node of the
  (A4) quadratures that the tables' ū, u1 and the effective medium's σ̄ are made of.
- :func:`k_table` / :func:`k_eval` — K(s0) = ∫_{s0}^∞ erf²(s) e^{-s²} ds / s (the
  Yang–Persson correction, doi:10.1088/0953-8984/20/21/215214), a cubic Hermite table in ln s0 with exact derivatives
  dK/d(ln s0) = -erf²(s0) e^{-s0²}, with the series below the table and
  E1(s0²)/2 above it; K(0) = 0.4071249346.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit

from .hermite import cubic_uniform
from .quadrature import gauss_legendre

__all__ = ["EULER_GAMMA", "K_ZERO", "KTable", "e1", "e1_and_exp", "erfinv", "k_eval", "k_table"]

EULER_GAMMA = 0.57721566490153286061

# K(s0) is tabulated directly for t = ln s0 in [_K_TMIN, 0] and as the ratio
# ρ = 2K/E1(s0²) (smooth, -> 1) for t in [0, _R_TMAX]; beyond, K = E1(s0²)/2 (erfc(20) ~ 1e-176).
_K_TMIN = -9.0
_K_N = 1801
_R_TMAX = math.log(20.0)
_R_N = 1201


#: Ein(x) = E1(x) + γ + ln x = Σ_{k>=1} (-1)^{k+1} x^k/(k k!): coefficients of x^1..x^18
#: (the truncation error is below 1e-17 for x <= 1)
_EIN = np.array([1.0, -0.25, 0.05555555555555555, -0.010416666666666666, 0.0016666666666666668,
                 -0.0002314814814814815, 2.834467120181406e-05, -3.1001984126984127e-06,
                 3.0619243582206544e-07, -2.755731922398589e-08, 2.27746439867652e-09,
                 -1.7397297489890083e-10, 1.2353110643708935e-11, -8.193389712664089e-13,
                 5.0981091545465446e-14, -2.9871733327421158e-15, 1.6537983849091297e-16,
                 -8.677337204770125e-18])
#: Chebyshev coefficients (degree 18) of f(x) = x e^x E1(x) on the octaves [2^j, 2^(j+1)],
#: j = 0..5, computed with mpmath at 40 digits; relative error <= 3e-16 on 1 <= x <= 64
_E1_CHEB = np.array([  # one row of 19 coefficients per octave j
    [0.6660290478589338, 0.06242528843863769, -0.006439971522584476, 0.0007188104965299417, -8.537148991010124e-05, 1.0648380975570468e-05, -1.380913541754629e-06, 1.8477934175040391e-07, -2.5364639654694244e-08, 3.556011564572035e-09, -5.074115309179287e-10, 7.349275201415118e-11, -1.0781522028500773e-11, 1.5992380275336405e-12, -2.3951290120264065e-13, 3.6176007444363476e-14, -5.5050424022705606e-15, 8.4286787323047e-16, -1.26838125034735e-16],
    [0.7802359009758556, 0.05057911157732128, -0.006113806466446871, 0.000769865860518743, -0.00010029543689856821, 1.3441723236134673e-05, -1.8447925285347979e-06, 2.5831692135853973e-07, -3.679358621999199e-08, 5.318025436335566e-09, -7.784409115294705e-10, 1.1520951705970714e-10, -1.7216711602482587e-11, 2.5948940877394413e-12, -3.940785937849547e-13, 6.025440629798345e-14, -9.268982377187794e-15, 1.4328919275353975e-15, -2.1742292093243532e-16],
    [0.8668048373433986, 0.03572951235592642, -0.004895924553521569, 0.0006834820096427278, -9.697663181268821e-05, 1.3956364689041613e-05, -2.0337277146399377e-06, 2.9963382373397474e-07, -4.4578239842876726e-08, 6.6899752178875105e-09, -1.0118056680552671e-09, 1.5409816786545457e-10, -2.3617216913952955e-11, 3.640264298734069e-12, -5.64007689190393e-13, 8.779862003914903e-14, -1.3726539489007141e-14, 2.1532724961072518e-15, -3.309322391889374e-16],
    [0.9246258127074481, 0.02242604690482162, -0.0033632854246972467, 0.000508112072411939, -7.727718728604625e-05, 1.1824509210703232e-05, -1.8193981013257861e-06, 2.8137342677733915e-07, -4.3718887142567354e-08, 6.822208735815323e-09, -1.0688256661208444e-09, 1.6806821429672257e-10, -2.651825887207594e-11, 4.1974007433524215e-12, -6.663420941745026e-13, 1.0607414891078441e-13, -1.6929049721392694e-14, 2.7066164997757565e-15, -4.230513851540919e-16],
    [0.9594354643424124, 0.012870093055632838, -0.0020471380915025174, 0.00032643986998048114, -5.217779673400878e-05, 8.358640902761557e-06, -1.3418329765298758e-06, 2.1583592432992e-07, -3.4782826071477125e-08, 5.61537387017273e-09, -9.080820839784113e-10, 1.4708451362146156e-10, -2.3859953703206606e-11, 3.876152254318246e-12, -6.305660621295098e-13, 1.0271423587581275e-13, -1.6752014629764496e-14, 2.7335525427326477e-15, -4.3520871817846673e-16],
    [0.978868882322758, 0.0069566873059839366, -0.001146032905484081, 0.00018894005274336037, -3.11725031859612e-05, 5.146701199393139e-06, -8.503257477789458e-07, 1.4058234058457857e-07, -2.3257108385731342e-08, 3.849914260603813e-09, -6.376877848978832e-10, 1.05686262251595e-10, -1.7525662865119025e-11, 2.9078249975341e-12, -4.827171477905108e-13, 8.017531431805837e-14, -1.3322845073089371e-14, 2.2133432723616535e-15, -3.582293226556552e-16],
])


def _chebyshev_to_monomial(c):
    """Coefficients a_k of Σ_k c_k T_k(t) = Σ_k a_k t^k: exact in rationals (the float c_k as
    given), each a_k then rounded once to the nearest double."""
    from fractions import Fraction
    n = len(c)
    T = [[Fraction(0)] * n for _ in range(n)]  # T[k][j]: coefficient of t^j in T_k
    T[0][0] = Fraction(1)
    if n > 1:
        T[1][1] = Fraction(1)
    for k in range(2, n):
        for j in range(n):
            T[k][j] = (2 * T[k - 1][j - 1] if j else Fraction(0)) - T[k - 2][j]
    return [float(sum(Fraction(float(c[k])) * T[k][j] for k in range(n))) for j in range(n)]


#: the octaves' fits of :data:`_E1_CHEB` in the monomial basis of t ∈ [-1, 1] (every |a_k| <= 0.98,
#: the value 0.67–0.98: Estrin's sums are as well conditioned as the Chebyshev sum)
_E1_MONO = np.array([_chebyshev_to_monomial(row) for row in _E1_CHEB])


@njit(cache=True, inline="always")
def _estrin16(a, t):
    """(Σ_{k<16} a[k] t^k by Estrin's scheme, t^16)."""
    t2 = t * t
    t4 = t2 * t2
    t8 = t4 * t4
    q0 = (a[0] + a[1] * t) + (a[2] + a[3] * t) * t2
    q1 = (a[4] + a[5] * t) + (a[6] + a[7] * t) * t2
    q2 = (a[8] + a[9] * t) + (a[10] + a[11] * t) * t2
    q3 = (a[12] + a[13] * t) + (a[14] + a[15] * t) * t2
    return (q0 + q1 * t4) + (q2 + q3 * t4) * t8, t8 * t8


@njit(cache=True, inline="always")
def _estrin18(a, t):
    """Σ_{k<18} a[k] t^k by Estrin's scheme."""
    s, t16 = _estrin16(a, t)
    return s + (a[16] + a[17] * t) * t16


@njit(cache=True, inline="always")
def _estrin19(a, t):
    """Σ_{k<19} a[k] t^k by Estrin's scheme."""
    s, t16 = _estrin16(a, t)
    return s + ((a[16] + a[17] * t) + a[18] * (t * t)) * t16


@njit(cache=True)
def e1_and_exp(x):
    """(E1(x), e^{-x}) for x > 0: power series (x <= 1), Chebyshev fits (x <= 64), else the
    Lentz continued fraction. Relative error <= 1e-15 (E1(0) = inf, E1 = 0 beyond x = 745)."""
    if x <= 0.0:
        return math.inf, 1.0
    if x <= 1.0:
        return -EULER_GAMMA - math.log(x) + x * _estrin18(_EIN, x), math.exp(-x)
    ex = math.exp(-x)
    if x <= 64.0:
        j = math.frexp(x)[1] - 1
        if j > 5:
            j = 5
        a = float(1 << j)
        t = (x - a) / a * 2.0 - 1.0  # octave [a, 2a] -> [-1, 1]
        return _estrin19(_E1_MONO[j], t) * ex / x, ex
    if x > 745.0:
        return 0.0, 0.0
    b = x + 1.0
    c = 1e300
    d = 1.0 / b
    h = d
    i = 1
    while True:
        an = -float(i * i)
        b += 2.0
        d = 1.0 / (an * d + b)
        c = b + an / c
        de = c * d
        h *= de
        if abs(de - 1.0) < 1e-16:
            break
        i += 1
    return h * ex, ex


@njit(cache=True)
def e1(x):
    """Exponential integral E1(x) for x > 0 (inf at 0, 0 beyond x = 745)."""
    return e1_and_exp(x)[0]


class KTable(NamedTuple):
    """The K(s0) Hermite tables: direct K on t = ln s0 in [tmin, 0], ratio ρ = 2K/E1(s0²) above."""

    tmin: float
    dt: float
    kval: np.ndarray
    kder: np.ndarray
    dtr: float
    rval: np.ndarray
    rder: np.ndarray


@lru_cache(maxsize=1)
def k_table() -> KTable:
    """(tmin, dt, K, dK/dt, dt_r, ρ, dρ/dt) of the K(s0) Hermite tables (built once, ~ms)."""
    import scipy.special as sp          # here, not at import: scipy.special and
    from scipy.integrate import quad    # scipy.integrate cost ~0.4 s to import
    gl_x, gl_w = gauss_legendre(12)
    # ---- ratio table on [0, _R_TMAX]
    tr = np.linspace(0.0, _R_TMAX, _R_N)
    dtr = tr[1] - tr[0]
    sr = np.exp(tr)
    # K at s = 20 from its definition by adaptive quadrature (erf² = 1 - 1e-176 there)
    k_top = quad(lambda x: sp.erf(x) ** 2 * math.exp(-x * x) / x, sr[-1], np.inf, epsabs=0.0,
                 epsrel=1e-13, limit=200)[0]
    kr = np.empty_like(tr)
    kr[-1] = k_top
    xs = 0.5 * (tr[1:] + tr[:-1])[:, None] + 0.5 * dtr * gl_x[None, :]
    ss = np.exp(xs)
    panel = 0.5 * dtr * np.sum(gl_w[None, :] * (sp.erf(ss) ** 2 * np.exp(-ss * ss)), axis=1)
    kr[:-1] = k_top + np.cumsum(panel[::-1])[::-1]
    dk_r = -sp.erf(sr) ** 2 * np.exp(-sr * sr)
    e1r = sp.exp1(sr * sr)
    rho = 2.0 * kr / e1r
    drho = (2.0 * dk_r + 2.0 * rho * np.exp(-sr * sr)) / e1r
    # ---- direct table on [_K_TMIN, 0]
    t = np.linspace(_K_TMIN, 0.0, _K_N)
    dt = t[1] - t[0]
    s = np.exp(t)
    kder = -sp.erf(s) ** 2 * np.exp(-s * s)
    xs = 0.5 * (t[1:] + t[:-1])[:, None] + 0.5 * dt * gl_x[None, :]
    ss = np.exp(xs)
    panel = 0.5 * dt * np.sum(gl_w[None, :] * (sp.erf(ss) ** 2 * np.exp(-ss * ss)), axis=1)
    kval = np.empty_like(t)
    kval[-1] = kr[0]
    kval[:-1] = kr[0] + np.cumsum(panel[::-1])[::-1]
    c = np.ascontiguousarray
    return KTable(float(t[0]), float(dt), c(kval), c(kder), float(dtr), c(rho), c(drho))


#: K(0) = ∫_0^∞ erf²(s) e^{-s²} ds/s, for tests and documentation
K_ZERO = 0.40712493463438924


#: old name of :func:`fastcontact.kernels.hermite.cubic_uniform`
hermite = cubic_uniform


@njit(cache=True)
def k_eval(s0, tmin, dt, kval, kder, dtr, rval, rder):
    """K(s0) = ∫_{s0}^∞ erf²(s) e^{-s²} ds/s from the tables of :func:`k_table`."""
    if s0 <= 0.0:
        smin = math.exp(tmin)
        return kval[0] + (2.0 / math.pi) * smin * smin - (5.0 / (3.0 * math.pi)) * smin ** 4
    t = math.log(s0)
    if t < tmin:
        # series: ∫_{s0}^{smin} erf² e^{-s²}/s ds = (2/π)(smin²-s0²) - (5/3π)(smin⁴-s0⁴) + O(s⁶)
        smin = math.exp(tmin)
        return (kval[0] + (2.0 / math.pi) * (smin * smin - s0 * s0)
                - (5.0 / (3.0 * math.pi)) * (smin ** 4 - s0 ** 4))
    if t <= 0.0:
        return cubic_uniform(t, tmin, dt, kval, kder)
    if t >= dtr * (rval.size - 1):
        return 0.5 * e1(s0 * s0)
    return 0.5 * e1(s0 * s0) * cubic_uniform(t, 0.0, dtr, rval, rder)


@njit(cache=True)
def erfinv(y):
    """Inverse error function on (-1, 1) by Newton iteration from Giles' approximation."""
    if y <= -1.0:
        return -math.inf
    if y >= 1.0:
        return math.inf
    w = -math.log((1.0 - y) * (1.0 + y))
    if w < 5.0:
        w -= 2.5
        p = 2.81022636e-08
        p = 3.43273939e-07 + p * w
        p = -3.5233877e-06 + p * w
        p = -4.39150654e-06 + p * w
        p = 0.00021858087 + p * w
        p = -0.00125372503 + p * w
        p = -0.00417768164 + p * w
        p = 0.246640727 + p * w
        p = 1.50140941 + p * w
    else:
        w = math.sqrt(w) - 3.0
        p = -0.000200214257
        p = 0.000100950558 + p * w
        p = 0.00134934322 + p * w
        p = -0.00367342844 + p * w
        p = 0.00573950773 + p * w
        p = -0.0076224613 + p * w
        p = 0.00943887047 + p * w
        p = 1.00167406 + p * w
        p = 2.83297682 + p * w
    x = p * y
    if abs(y) <= 0.5:
        for _ in range(4):
            x -= (math.erf(x) - y) / (2.0 / math.sqrt(math.pi) * math.exp(-x * x))
        return x
    # tails: Newton on ln erfc(|x|) = ln(1 - |y|), well conditioned up to |y| -> 1
    sgn = 1.0 if y > 0 else -1.0
    ax = abs(x)
    target = math.log(1.0 - abs(y))
    for _ in range(60):
        ec = math.erfc(ax)
        f = math.log(ec) - target
        dfdx = -2.0 / math.sqrt(math.pi) * math.exp(-ax * ax) / ec
        step = f / dfdx
        ax -= step
        if abs(step) < 1e-15 * ax:
            break
    return sgn * ax
