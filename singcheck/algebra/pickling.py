"""Pickling of python-flint's exact types, so that a robot and its trajectories cross a
process boundary (a Dask cluster ships them to its workers).

python-flint's polynomial contexts and polynomials do not pickle by themselves; these
reducers rebuild each one exactly from its terms (rational coefficients and exponent
vectors), its context from its variable names and ordering.  :func:`register` installs
them in :mod:`copyreg` (pickle and cloudpickle both consult it) when this module is
imported; nothing is rounded.
"""

from __future__ import annotations

import copyreg

from flint import arb, fmpq, fmpq_mpoly, fmpq_mpoly_ctx, fmpq_poly, fmpz_mpoly, fmpz_mpoly_ctx


def _ctx(kind, names: tuple[str, ...], ordering: str, opaque: dict | None = None):
    if opaque:  # the functions behind a path ring's opaque variables, registered again
        from singcheck.algebra.opaque import register_opaque

        for name, (function, what) in opaque.items():
            register_opaque(name, function, what)
    return kind.get(names, ordering)


def _reduce_ctx(ctx):
    """The context by its names; a path ring's opaque variables (coordinates kept as
    expression trees, :mod:`singcheck.algebra.opaque`) travel with their functions."""
    from singcheck.algebra.opaque import opaque_of

    names = tuple(ctx.names())
    opaque = {n: opaque_of(n) for n in names if opaque_of(n) is not None}
    return _ctx, (type(ctx), names, ctx.ordering().name, opaque or None)


def _mpoly(ctx, terms: dict):
    return ctx.from_dict(terms)


def _plain(ctx):
    """``ctx`` with its variables renamed v00, v01, …: names of one width made of letters
    and digits only, which FLINT's parser cannot confuse (a name such as ``cos(phi)`` or
    ``sqrt(3)`` holds operators, and ``s`` is a prefix of ``sqrt(3)``)."""
    width = len(str(ctx.nvars()))
    return type(ctx).get(tuple(f"v{i:0{width}d}" for i in range(ctx.nvars())),
                         ctx.ordering().name)


def _mpoly_text(ctx, text: str):
    plain = _plain(ctx)
    kind = fmpq_mpoly if isinstance(ctx, fmpq_mpoly_ctx) else fmpz_mpoly
    return kind(text, plain).project_to_context(
        ctx, mapping=dict(zip(plain.names(), ctx.names(), strict=True)))


def _reduce_mpoly(p):
    """The polynomial as FLINT's own exact text (integers and fractions in full) in the
    renamed context: written and parsed in C, several times faster than a dictionary of
    FLINT numbers for the tens of thousands of terms of a ξ that crosses a fork."""
    ctx = p.context()
    plain = _plain(ctx)
    text = str(p.project_to_context(plain, mapping=dict(zip(ctx.names(), plain.names(),
                                                            strict=True))))
    return _mpoly_text, (ctx, text)


def _fmpq_poly(coefficients: list):
    return fmpq_poly(coefficients)


def _reduce_fmpq_poly(p):
    return _fmpq_poly, ([fmpq(c) for c in p.coeffs()],)


def _arb(mid: tuple[int, int], rad: tuple[int, int]):
    return arb(mid, rad)


def _reduce_arb(x):
    """Exact midpoint; the radius as arb stores it (an upper bound), so the ball is the
    same ball."""
    mid, rad = x.mid().man_exp(), x.rad().man_exp()
    return _arb, ((int(mid[0]), int(mid[1])), (int(rad[0]), int(rad[1])))


def register() -> None:
    """Install the reducers (idempotent)."""
    for kind in (fmpq_mpoly_ctx, fmpz_mpoly_ctx):
        copyreg.pickle(kind, _reduce_ctx)
    for kind in (fmpq_mpoly, fmpz_mpoly):
        copyreg.pickle(kind, _reduce_mpoly)
    copyreg.pickle(fmpq_poly, _reduce_fmpq_poly)
    copyreg.pickle(arb, _reduce_arb)


# Installed on import: a process that unpickles a robot (a Dask worker) imports this
# module for the rebuilders above, and can then pickle it again (to another worker).
register()
