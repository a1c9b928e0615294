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


def _ctx(kind, names: tuple[str, ...], ordering: str):
    return kind.get(names, ordering)


def _reduce_ctx(ctx):
    return _ctx, (type(ctx), tuple(ctx.names()), ctx.ordering().name)


def _mpoly(ctx, terms: dict):
    return ctx.from_dict(terms)


def _reduce_mpoly(p):
    return _mpoly, (p.context(), {tuple(int(e) for e in k): v for k, v in p.to_dict().items()})


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
