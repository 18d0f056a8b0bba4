"""A gear pair given by its transmission law (issue 35): the follower's angle as a function
of the driver's, or the ratio, as an expression or a table; read by ``design_planetary``
(``GearPair.law``) and turned into the driver's pitch curve by ``trains.spec``.

Expressions are read by a restricted grammar, never ``eval``: numbers, the driver angle
``t`` (rad), ``pi``, ``e``, the file's named ``constants``, + - * / ** and unary minus,
and the functions of ``FUNCTIONS`` (NumPy's, element-wise). Anything else (attributes,
subscripts, comparisons, names not listed, calls of anything else, keywords) is refused
with the place it occurs (``ExpressionError``).

A law over one driver turn, with the turns n1:n2 (the driver makes n1 turns while the
follower makes n2, q = n2 / n1 follower turns per driver turn): the ratio g(t) = d phi / dt
repeats every 360 / n2 deg of driver angle (the driver then carries n2 identical lobes and
the follower n1), and the follower turns 360 / n1 deg over each such lobe. ``sample_law``
tabulates phi's periodic part, its slope g and g' on the train's grid (spectrally, by FFT,
for an expression; a periodic cubic spline's exact derivatives for a table) and refuses,
naming the driver angle, a law whose ratio reaches zero or changes sign, one that is not
finite, and one that does not repeat as the turns ask.

An open segment (``segment_deg = [t0, t1]``): the law is wanted over driver angles t0..t1
only (a function generator, a quick return's working stroke); the pair is made a whole
gear pair by a return arc over the rest of the turn, the cubic of the ratio that joins
the segment's ends (value and slope) and closes the pair (the follower turns 360 / n1 deg
per driver turn in all), itself refused when its ratio would not stay positive.
"""

from __future__ import annotations

import ast

import numpy as np

TWO_PI = 2.0 * np.pi

#: the functions an expression may call (element-wise, radians)
FUNCTIONS = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
    "atan": np.arctan, "atan2": np.arctan2, "sinh": np.sinh, "cosh": np.cosh,
    "tanh": np.tanh, "exp": np.exp, "log": np.log, "sqrt": np.sqrt, "abs": np.abs,
    "hypot": np.hypot,
}
CONSTANTS = {"pi": np.pi, "e": np.e}
#: the longest expression read, and its deepest nesting
MAX_EXPRESSION = 2000
MAX_DEPTH = 40

_BINARY = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
           ast.Div: np.divide, ast.Pow: np.power}


class ExpressionError(ValueError):
    """An expression outside the grammar (message names what and where)."""


class LawError(ValueError):
    """A law that cannot be a gear pair (message names the driver angle)."""


def compile_expression(text: str, names: dict[str, float] | None = None):
    """A function of the driver angle t (rad, an array) for ``text``; ExpressionError
    naming the first part outside the grammar (module docstring)."""
    if len(text) > MAX_EXPRESSION:
        raise ExpressionError(f"longer than {MAX_EXPRESSION} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"not an expression: {exc.msg} at column {exc.offset}") from None
    values = dict(CONSTANTS)
    for k, v in (names or {}).items():
        if k in FUNCTIONS or k == "t":
            raise ExpressionError(f"constant '{k}' would hide the function or the driver "
                                  "angle of that name")
        values[k] = float(v)
    _check(tree.body, values, 0)
    body = tree.body

    def f(t):
        with np.errstate(all="ignore"):
            return np.broadcast_to(_eval(body, np.asarray(t, dtype=float), values),
                                   np.shape(t)).astype(float)

    return f


def _where(node) -> str:
    return f"column {getattr(node, 'col_offset', 0) + 1}"


def _check(node, values: dict, depth: int) -> None:
    if depth > MAX_DEPTH:
        raise ExpressionError(f"nested deeper than {MAX_DEPTH} levels")
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, int | float):
            raise ExpressionError(f"{node.value!r} at {_where(node)} is not a number")
        return
    if isinstance(node, ast.Name):
        if node.id != "t" and node.id not in values:
            raise ExpressionError(f"unknown name '{node.id}' at {_where(node)} (the driver "
                                  "angle is t, rad; constants: pi, e and the law's "
                                  "'constants'; functions: " + ", ".join(FUNCTIONS) + ")")
        return
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        _check(node.left, values, depth + 1)
        _check(node.right, values, depth + 1)
        return
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        _check(node.operand, values, depth + 1)
        return
    if isinstance(node, ast.Call):
        name = node.func.id if isinstance(node.func, ast.Name) else None
        if name not in FUNCTIONS:
            raise ExpressionError(f"call at {_where(node)} is not one of the functions "
                                  + ", ".join(FUNCTIONS))
        if node.keywords:
            raise ExpressionError(f"{name}() at {_where(node)} takes no keywords")
        wanted = 2 if name in ("atan2", "hypot") else 1
        if len(node.args) != wanted:
            raise ExpressionError(f"{name}() at {_where(node)} takes {wanted} argument(s), "
                                  f"got {len(node.args)}")
        for a in node.args:
            _check(a, values, depth + 1)
        return
    raise ExpressionError(f"'{ast.unparse(node)}' at {_where(node)} is outside the grammar "
                          "(numbers, t, constants, + - * / **, the listed functions)")


def _eval(node, t, values):
    if isinstance(node, ast.Constant):
        return float(node.value)
    if isinstance(node, ast.Name):
        return t if node.id == "t" else values[node.id]
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_eval(node.left, t, values),
                                      _eval(node.right, t, values))
    if isinstance(node, ast.UnaryOp):
        v = _eval(node.operand, t, values)
        return -v if isinstance(node.op, ast.USub) else v
    return FUNCTIONS[node.func.id](*(_eval(a, t, values) for a in node.args))


def _deg(theta: float) -> str:
    return f"{np.degrees(theta):.3f} deg"


def _spectral(periodic: np.ndarray, orders: int = 2) -> list[np.ndarray]:
    """The first ``orders`` derivatives (per rad) of a periodic table on the uniform grid
    over one turn (FFT; the Nyquist term dropped)."""
    N = periodic.size
    c = np.fft.rfft(periodic)
    k = np.fft.rfftfreq(N, 1.0 / N)
    if N % 2 == 0:
        c[-1] = 0.0
    return [np.fft.irfft(c * (1j * k) ** o, N) for o in range(1, orders + 1)]


def _sign_change(g: np.ndarray, theta: np.ndarray) -> tuple[float, str] | None:
    """(driver angle, what) where the ratio first reaches zero or changes sign."""
    bad = np.flatnonzero(g <= 0)
    if not bad.size:
        return None
    i = int(bad[0])
    if i == 0:
        return float(theta[0]), ("reaches zero" if g[0] == 0 else "is negative")
    g0, g1 = g[i - 1], g[i]
    at = theta[i - 1] + (theta[i] - theta[i - 1]) * g0 / (g0 - g1)
    return float(at), ("reaches zero" if g1 == 0 else "changes sign")


def sample_law(law, grid: int, n1: int, n2: int, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(g, dg/dt) (grid,) of a ``design_planetary.TransmissionLaw`` on the driver's grid
    t_k = 2 pi k / grid (rad) over one driver turn, the driver making n1 turns while the
    follower makes n2. LawError (naming ``where`` and the driver angle) for a law that is
    not finite, whose ratio reaches zero or changes sign, or that does not repeat as the
    turns ask (module docstring)."""
    q = n2 / n1
    lobe = TWO_PI / n2
    theta = TWO_PI * np.arange(grid) / grid
    if law.segment_deg is not None:
        return _segment(law, grid, q, where)
    if law.follower_deg is not None or law.ratio_table is not None:
        return _table(law, grid, n1, n2, where)
    names = law.constants or {}
    if law.follower_angle is not None:
        phi = compile_expression(law.follower_angle, names)
        # over a lobe, densely, unwrapped: an expression written with a branch (2 atan(k
        # tan(t / 2)) jumps by 2 pi at t = 180 deg) is read as the continuous law
        lobe_t = np.linspace(0.0, lobe, max(grid // n2, 16) + 1)
        ends = np.unwrap(phi(lobe_t))
        _finite(ends, lobe_t, where, "follower_angle")
        values = phi(theta)
        _finite(values, theta, where, "follower_angle")
        values = np.unwrap(values)
        span = float(ends[-1] - ends[0])
        if not np.isfinite(span) or abs(span - TWO_PI / n1) > 1e-9 * max(1.0, abs(span)):
            raise LawError(f"{where}: the law turns the follower {np.degrees(span):.6g} deg "
                           f"while the driver turns {360 / n2:g} deg (from 0 to "
                           f"{360 / n2:g} deg); the turns {n1}:{n2} ask "
                           f"{360 / n1:g} deg (the law does not repeat as the turns ask)")
        periodic = values - values[0] - q * theta
        g1, g2 = _spectral(periodic)
        g = q + g1
        dg = g2
    else:
        ratio = compile_expression(law.ratio, names)
        g = ratio(theta)
        _finite(g, theta, where, "ratio")
        mean = float(np.mean(g))
        if abs(mean - q) > 1e-9 * q:
            raise LawError(f"{where}: the ratio's mean over a driver turn is {mean:.9g}: the "
                           f"follower would turn {360 * mean:.6g} deg per driver turn, the "
                           f"turns {n1}:{n2} ask {360 * q:.6g} deg")
        (dg,) = _spectral(g - mean, 1)
    bad = _sign_change(g, theta)
    if bad is not None:
        raise LawError(f"{where}: the law's ratio (follower speed / driver speed) {bad[1]} at "
                       f"driver angle {_deg(bad[0])}: a gear pair turns its follower one "
                       "way at a finite, positive ratio")
    _repeats(g, theta, n2, where)
    return g, dg


def _finite(values, theta, where, what) -> None:
    bad = ~np.isfinite(values)
    if bad.any():
        raise LawError(f"{where}.{what}: not finite at driver angle "
                       f"{_deg(theta[int(np.argmax(bad))])}")


def _repeats(g: np.ndarray, theta: np.ndarray, n2: int, where: str) -> None:
    N = g.size
    if n2 == 1:
        return
    shift = N / n2
    if shift != int(shift):
        raise LawError(f"{where}: train.grid = {N} is not a multiple of the follower's "
                       f"turns {n2} (the law's lobes)")
    gap = np.abs(np.roll(g, -int(shift)) - g)
    i = int(np.argmax(gap))
    if gap[i] > 1e-6 * np.abs(g).max():
        raise LawError(f"{where}: the ratio at driver angle {_deg(theta[i])} is {g[i]:.6g} and "
                       f"{360 / n2:g} deg later {g[(i + int(shift)) % N]:.6g}: with turns "
                       f"n1:{n2} it must repeat every {360 / n2:g} deg (the law does not "
                       "repeat as the turns ask)")


def _table(law, grid: int, n1: int, n2: int, where: str):
    """A tabulated law over one lobe (0 to 360 / n2 deg of driver angle): the follower's
    angle (its periodic part by a periodic cubic spline) or the ratio (periodic spline)."""
    from scipy.interpolate import CubicSpline

    q = n2 / n1
    lobe = TWO_PI / n2
    x = np.radians(np.asarray(law.driver_deg, dtype=float))
    theta = TWO_PI * np.arange(grid) / grid
    u = np.mod(theta - x[0], lobe) + x[0]
    if abs((x[-1] - x[0]) - lobe) > 1e-9:
        raise LawError(f"{where}.driver_deg: the table spans {np.degrees(x[-1] - x[0]):.6g} "
                       f"deg; with turns {n1}:{n2} it spans one lobe, {360 / n2:g} deg "
                       "(first and last rows: the same point of the law)")
    if law.follower_deg is not None:
        y = np.radians(np.asarray(law.follower_deg, dtype=float))
        span = y[-1] - y[0]
        if abs(span - TWO_PI / n1) > 1e-9:
            raise LawError(f"{where}.follower_deg: the follower turns {np.degrees(span):.6g} "
                           f"deg over the table's {360 / n2:g} deg of driver angle; the "
                           f"turns {n1}:{n2} ask {360 / n1:g} deg (the law does not repeat "
                           "as the turns ask)")
        p = y - y[0] - q * (x - x[0])
        p[-1] = p[0]
        s = CubicSpline(x, p, bc_type="periodic")
        g, dg = q + s(u, 1), s(u, 2)
    else:
        y = np.asarray(law.ratio_table, dtype=float)
        if abs(y[-1] - y[0]) > 1e-12 * abs(y).max():
            raise LawError(f"{where}.ratio_table: the last ratio {y[-1]:.6g} is not the "
                           f"first {y[0]:.6g}: the law repeats every {360 / n2:g} deg")
        s = CubicSpline(x, y, bc_type="periodic")
        mean = float(s.integrate(x[0], x[-1]) / lobe)
        if abs(mean - q) > 1e-9 * q:
            raise LawError(f"{where}.ratio_table: the ratio's mean is {mean:.9g}: the "
                           f"follower would turn {360 * mean:.6g} deg per driver turn, the "
                           f"turns {n1}:{n2} ask {360 * q:.6g} deg")
        g, dg = s(u), s(u, 1)
    bad = _sign_change(g, theta)
    if bad is not None:
        raise LawError(f"{where}: the law's ratio {bad[1]} at driver angle {_deg(bad[0])}")
    return g, dg


def _segment(law, grid: int, q: float, where: str):
    """An open segment: the law over [t0, t1] and a return arc closing the turn (module
    docstring)."""
    t0, t1 = np.radians(law.segment_deg)
    span = t1 - t0
    theta = TWO_PI * np.arange(grid) / grid
    u = np.mod(theta - t0, TWO_PI)  # driver angle past the segment's start
    inside = u <= span
    names = law.constants or {}
    if law.follower_angle is not None:
        phi = compile_expression(law.follower_angle, names)
        h = 1e-4
        probe = t0 + np.linspace(0.0, span, 4097)
        vals = np.unwrap(phi(probe))
        _finite(vals, probe, where, "follower_angle")
        d = lambda x: (phi(x - 2 * h) - 8 * phi(x - h) + 8 * phi(x + h)  # noqa: E731
                       - phi(x + 2 * h)) / (12 * h)
        ratio = d
        turned = float(vals[-1] - vals[0])
    elif law.ratio is not None:
        ratio = compile_expression(law.ratio, names)
        probe = t0 + np.linspace(0.0, span, 4097)
        _finite(ratio(probe), probe, where, "ratio")
        from scipy.integrate import quad

        turned = quad(lambda x: float(ratio(np.array([x]))[0]), t0, t1, limit=200)[0]
    else:
        raise LawError(f"{where}.segment_deg: an open segment takes follower_angle or ratio "
                       "(an expression)")
    probe = t0 + np.linspace(0.0, span, 8193)
    gs = ratio(probe)
    bad = _sign_change(gs, probe)
    if bad is not None:
        raise LawError(f"{where}: the law's ratio (follower speed / driver speed) {bad[1]} at "
                       f"driver angle {_deg(bad[0])}: a gear pair turns its follower one "
                       "way at a finite, positive ratio")
    rest = TWO_PI - span
    left = TWO_PI * q - turned  # what the return arc must turn the follower
    if left <= 0:
        raise LawError(f"{where}: the segment turns the follower {np.degrees(turned):.6g} "
                       f"deg, all of the {360 * q:.6g} deg the turns allow per driver turn: "
                       "no return arc can close the pair")
    h = 1e-5
    ga, gb = (float(v) for v in ratio(np.array([t1, t0])))
    da = float((ratio(np.array([t1 + h])) - ratio(np.array([t1 - h])))[0] / (2 * h))
    db = float((ratio(np.array([t0 + h])) - ratio(np.array([t0 - h])))[0] / (2 * h))
    # return arc over s in [0, rest]: cubic Hermite (ga, da) -> (gb, db) plus c s^2 (rest - s)^2
    s = np.where(inside, 0.0, u - span)
    x = s / rest
    h00, h10 = 2 * x**3 - 3 * x**2 + 1, x**3 - 2 * x**2 + x
    h01, h11 = -2 * x**3 + 3 * x**2, x**3 - x**2
    base = h00 * ga + h10 * rest * da + h01 * gb + h11 * rest * db
    base_int = rest * (ga + gb) / 2 + rest**2 * (da - db) / 12
    bump = s**2 * (rest - s) ** 2
    c = (left - base_int) / (rest**5 / 30)
    g_ret = base + c * bump
    d00, d10 = (6 * x**2 - 6 * x) / rest, 3 * x**2 - 4 * x + 1
    d01, d11 = (-6 * x**2 + 6 * x) / rest, 3 * x**2 - 2 * x
    dg_ret = d00 * ga + d10 * da + d01 * gb + d11 * db + c * (
        2 * s * (rest - s) ** 2 - 2 * s**2 * (rest - s))
    g_in = ratio(np.where(inside, theta, t0))
    dg_in = (ratio(theta + h) - ratio(theta - h)) / (2 * h)
    g = np.where(inside, g_in, g_ret)
    dg = np.where(inside, dg_in, dg_ret)
    if np.any(g_ret[~inside] <= 0):
        i = int(np.flatnonzero(~inside & (g_ret <= 0))[0])
        raise LawError(f"{where}: the return arc that closes the pair (the follower turning "
                       f"the remaining {np.degrees(left):.6g} deg over {np.degrees(rest):.6g} "
                       f"deg of driver turn) would need a ratio {g_ret[i]:.4g} at driver "
                       f"angle {_deg(theta[i])}; widen or move the segment")
    return g, dg
