"""One way to write a number on a page, the index, the diff and the figures.

Guarantees (what ``tests/report/test_no_roundoff.py`` checks on every text node of a built
site):

* no scientific notation: ``num`` writes fixed-point decimals to ``digits`` significant digits
  (``0.0003283``, ``54.62``, ``136300``); only magnitudes beyond a millionth or a thousand
  million of their unit, which no planar machine's quantity reaches except as round-off,
  fall back to a power of ten written out (``2.7×10⁻¹¹``);
* round-off is never shown as a value: a number at most :data:`FLOOR` (1e-9, the balance
  tolerance's default) times its quantity's scale is ``0`` (:func:`num_at`), a ratio at most
  its floor is ``0 (< 1e-9)`` (:func:`ratio`);
* one ratio convention: a value relative to its reference is a percentage below
  :data:`TIMES_FROM` (ten) times and a factor ``× 41.7`` from there on (:func:`ratio`); a cost,
  the balanced design's value over the unbalanced one's, is always a factor (:func:`factor`);
* thresholds and tolerances (settings, not results) read as written in a spec: ``1e-9``
  (:func:`tol`).
"""

from __future__ import annotations

import math

#: the relative floor below which a computed value is round-off of its quantity's scale (the
#: engine's balance tolerance by default; a spec's own tolerance where a caller has it)
FLOOR = 1e-9
#: ratios are percent below this many times their reference, a factor "×" from there on
TIMES_FROM = 10.0

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _special(x) -> tuple[float, str | None]:
    """``x`` as a float, and its text when that needs no formatting: '—' for None, 'nan' or
    'inf', '0' for zero (else None)."""
    if x is None:
        return 0.0, "—"
    v = float(x)
    if not math.isfinite(v):
        return v, str(v)
    return v, "0" if v == 0 else None


def power_of_ten(x: float, digits: int = 2) -> str:
    """``x`` as mantissa × a written-out power of ten: 2.753e-11 -> '2.8×10⁻¹¹', 1e-9 -> '1×10⁻⁹'."""
    m, _, e = f"{x:.{max(0, digits - 1)}e}".partition("e")
    if "." in m:
        m = m.rstrip("0").rstrip(".")
    return f"{m}×10{str(int(e)).translate(_SUPERSCRIPT)}"


def beyond(x: float) -> str:
    """The power of ten that a large positive ``x`` exceeds, written out: 3.58e14 -> '10¹⁴'
    (for margins such as a singular-value gap, where the order is what matters)."""
    return f"10{str(math.floor(math.log10(x))).translate(_SUPERSCRIPT)}"


def num(x, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits in fixed-point decimals, trailing zeros dropped:
    0.0789, 54.62, 136300 (never '1.363e+05'); '—' for None; magnitudes below 1e-6 or from 1e9
    as a written-out power of ten (:func:`power_of_ten`)."""
    v, special = _special(x)
    if special is not None:
        return special
    r = float(f"{v:.{digits - 1}e}")  # rounded to the significant digits
    a = abs(r)
    if a < 1e-6 or a >= 1e9:
        return power_of_ten(v, digits)
    e = math.floor(math.log10(a))
    decimals = max(0, digits - 1 - e)
    text = f"{r:.{decimals}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "0") else text


def roundoff(x, scale, floor: float = FLOOR) -> bool:
    """Whether ``x`` is round-off of a quantity of size ``scale``: ``|x| <= floor |scale|``
    (False when the scale is unknown or zero, or ``x`` is None)."""
    if x is None or scale is None or not scale:
        return False
    return abs(float(x)) <= floor * abs(float(scale))


def num_at(x, scale, digits: int = 4, floor: float = FLOOR) -> str:
    """:func:`num`, or '0' when ``x`` is round-off of ``scale`` (:func:`roundoff`)."""
    return "0" if roundoff(x, scale, floor) else num(x, digits)


def point(p, digits: int = 4) -> str:
    """A position '(x, y)' (no unit): a coordinate at most :data:`FLOOR` times the other is
    round-off of the computation and reads 0: (-0.08, 9.797e-18) -> '(-0.08, 0)'."""
    x, y = float(p[0]), float(p[1])
    scale = max(abs(x), abs(y))
    return f"({num_at(x, scale, digits)}, {num_at(y, scale, digits)})"


def scales_by_unit(values, base: dict | None = None) -> dict[str, float]:
    """The scale of each unit among ``values`` ((value, unit) pairs, a study's computed
    parameters): the largest magnitude of that unit, at least its ``base`` scale (the
    mechanism's moving mass for 'kg', ...) and at least 1 for dimensionless ones (unit ''): a
    value at most 1e-9 of its unit's scale is round-off (:func:`num_at`)."""
    out: dict[str, float] = {u: abs(float(v)) for u, v in (base or {}).items() if v is not None}
    for v, u in values:
        if v is not None and math.isfinite(float(v)):
            out[u or ""] = max(out.get(u or "", 0.0), abs(float(v)))
    out[""] = max(out.get("", 0.0), 1.0)
    return out


def tol(x) -> str:
    """A tolerance or threshold as written in a spec: 1e-09 -> '1e-9', 1000.0 -> '1000',
    0.005 -> '0.005', 1.56e-05 -> '0.0000156'."""
    if x is None:
        return "—"
    v = float(x)
    m, _, e = f"{v:.3g}".partition("e")
    return f"1e{int(e)}" if m == "1" and e and int(e) < 0 else num(v, 3)


def ratio(x, floor: float | None = FLOOR) -> str:
    """A value relative to its reference, the site's one convention: '0 (< 1e-9)' at or below
    ``floor`` (round-off; None: no floor), a percentage below :data:`TIMES_FROM` times
    ('35.2 %', '674 %'), a factor from there on ('× 41.7')."""
    v, special = _special(x)
    if special is not None:
        return special
    if floor is not None and abs(v) <= floor:
        return f"0 (< {tol(floor)})"
    if abs(v) >= TIMES_FROM:
        return f"× {num(v, 3)}"
    return f"{num(100 * v)} %"


def factor(x) -> str:
    """A cost factor, the balanced design's value over the unbalanced one's: '× 1.85' (three
    significant digits), '—' if unknown."""
    return "—" if x is None else f"× {num(x, 3)}"
