"""Opaque variables of a path ring: coordinates known only as ball functions of t.

A path coordinate that is not a polynomial in (t, sin t, cos t) over Q (``cos(t - 1)``:
:mod:`singcheck.spec.real_paths`) stands in the path ring as one variable whose name is
registered here with the function that encloses it: ``X[[…]]`` for a coordinate,
``A[[…]]``/``C[[…]]``/``S[[…]]`` for an angle, its cosine and its sine.  A robot's
parameter whose value is outside the exact field (``l: 2*cos(1/10)``:
:mod:`singcheck.spec.real_constants`) is ``K[[…]]``, a constant: a variable of the
robot's ring (and of a path ring it is carried into), whose ball is its value's at
every t.  Ball evaluation
(:func:`~singcheck.algebra.radicals.evaluate_path`) reads :func:`opaque_ball`; nothing
exact (μ, root isolation) ever takes such a ring (:func:`is_opaque` says so).

A registered function ``f`` has ``text``, ``constants``, ``f(t)`` (an enclosure over the
ball ``t``) and ``f.with_derivative(t)`` (enclosures of f and f').
"""

from __future__ import annotations

from flint import arb

#: opaque ring variable name -> (function, what the variable is: X, A, C or S)
_OPAQUE: dict[str, tuple[object, str]] = {}
#: the bracket characters of an opaque name (never in a polynomial variable's name)
OPEN, CLOSE = "[[", "]]"


def opaque_name(kind: str, f) -> str:
    """The path ring variable standing for f (``X``), or for the angle f, its cosine or
    its sine (``A``, ``C``, ``S``); registered for :func:`opaque_of`."""
    tag = f.text if not f.constants else f"{f.text} | " + ", ".join(
        f"{k}={v}" for k, v in f.constants)
    name = f"{kind}{OPEN}{tag}{CLOSE}"
    _OPAQUE.setdefault(name, (f, kind))
    return name


def register_opaque(name: str, f, kind: str) -> None:
    """Register a name built by :func:`opaque_name` in another process (unpickling)."""
    _OPAQUE.setdefault(name, (f, kind))


def opaque_of(name: str) -> tuple[object, str] | None:
    """(function, kind) of an opaque variable's name, None for any other name."""
    return _OPAQUE.get(name) if name.endswith(CLOSE) else None


def is_opaque_constant(name: str) -> bool:
    """Whether ``name`` is a robot's opaque constant (``K[[…]]``)."""
    hit = opaque_of(name)
    return hit is not None and hit[1] == "K"


def has_opaque_coordinates(ctx) -> bool:
    """Whether a ring has opaque variables that vary with t (coordinates kept as
    expression trees; a robot's opaque constants ``K[[…]]`` do not count)."""
    return any(n.endswith(CLOSE) and not n.startswith("K" + OPEN) for n in ctx.names())


def is_opaque(ctx) -> bool:
    """Whether a ring has opaque variables (a path the exact engine cannot take)."""
    return any(n.endswith(CLOSE) for n in ctx.names())


def opaque_rate(name: str, t: arb) -> arb:
    """d/dt of an opaque variable over the ball ``t`` (an angle's cos: −sin·A', ...)."""
    f, kind = _OPAQUE[name]
    value, rate = f.with_derivative(t)
    if kind == "C":
        return -value.sin() * rate
    if kind == "S":
        return value.cos() * rate
    return rate


def opaque_ball(name: str, t: arb) -> arb:
    """The ball of an opaque variable over the ball ``t``."""
    f, kind = _OPAQUE[name]
    value = f(t)
    if kind == "C":
        return value.cos()
    if kind == "S":
        return value.sin()
    return value
