"""Which region holds a rational point: a decomposition's levels and region numbers.

A :class:`RegionMap` keeps what locating a point needs from a
:class:`~singcheck.space_analysis.SpaceAnalysis` — the projection levels of its open CAD
and the region number of every cell — and nothing else, so that it can be stored.  A
rational point is located exactly: at each level its coordinate is compared with the
real roots of the level's factors over the coordinates before it (exact isolation);
a point on a root lies on no open cell and is not located.

The map is cached on disk beside the elimination cache (a 3-D decomposition with its
regions takes seconds; reading it back, milliseconds).  An entry is keyed by the SHA-256
of the variety's polynomials, the slice and :data:`REGIONS_VERSION`, and carries an HMAC
of its payload under the cache's secret key (:mod:`singcheck.elimination.cache`): a
damaged entry, or one forged by anyone who cannot read that key, is ignored and
recomputed.  A loaded map is also checked against its inputs (:meth:`RegionMap.verify`,
against the open CAD recomputed from the variety: 2–6 % of the cost of computing the
map), so that even an entry sealed with the right key cannot relabel, renumber or
re-sign regions; a map that fails is recomputed.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.elimination.cas.polytext import (
    PolynomialSyntaxError,
    format_polynomial,
    parse_polynomial,
)

#: Bump when the decomposition or the joining of regions changes what a number means.
REGIONS_VERSION = "2"
FORMAT = "singcheck-region-map/2"


@dataclass(frozen=True)
class RegionMap:
    variables: tuple[str, ...]
    levels: tuple[tuple[fmpq_mpoly, ...], ...]
    factors: tuple[fmpq_mpoly, ...]  # the variety's factors (for ball proofs near a point)
    numbers: dict[tuple[int, ...], int]  # cell index -> region number

    @classmethod
    def of(cls, analysis) -> RegionMap:
        cad = analysis.cad
        numbers = {c.index: r.number for r in analysis.regions.regions for c in r.cells}
        return cls(cad.variables, cad.levels, cad.factors, numbers)

    def region_at(self, point: list[Fraction]) -> int | None:
        """The region of the open cell holding a rational point (None on a root)."""
        from singcheck.spaces.cad import cell_index_of, fiber  # (not for runs that never ask)

        index = cell_index_of(lambda p: fiber(self.levels, self.variables, p), tuple(point))
        return None if index is None else self.numbers.get(index)

    def verify(self, cad) -> str:
        """Check this map against ``cad``, the open CAD recomputed from the map's inputs
        (:func:`~singcheck.spaces.analysis.decomposition`: milliseconds, against seconds
        for joining the regions); "" when it holds, else what is wrong.

        Checked exactly: the factors and every projection level are those of the
        inputs; the map numbers exactly the CAD's cells; the numbers are 1…N in the
        order of each region's first cell (the rule regions are numbered by); and the
        cells of one region have the same sign of every factor at their samples (a
        connected set off the variety cannot change sign).  So a relabelled, renumbered
        or re-signed entry is caught; what is trusted (HMAC) is only which cells of the
        same signs were joined into one region.
        """
        if tuple(cad.variables) != self.variables:
            return "its axes are not the slice's"
        if set(map(format_polynomial, cad.factors)) != set(map(format_polynomial, self.factors)):
            return "its factors are not those of the variety"
        if len(cad.levels) != len(self.levels) or any(
                set(map(format_polynomial, a)) != set(map(format_polynomial, b))
                for a, b in zip(cad.levels, self.levels, strict=True)):
            return "its projection levels are not those of the variety"
        samples = {c.index: c.sample for c in cad.cells}
        if set(samples) != set(self.numbers):
            return "its cells are not the decomposition's"
        regions: dict[int, list[tuple[int, ...]]] = {}
        for index in sorted(self.numbers):
            regions.setdefault(self.numbers[index], []).append(index)
        if list(regions) != list(range(1, len(regions) + 1)):
            return "its regions are not numbered 1, 2, … in the order of their first cell"
        from singcheck.spaces.regions import factor_signs

        for number, cells in regions.items():
            signs = {factor_signs(cad, samples[index]) for index in cells}
            if len(signs) > 1:
                return f"region R{number} has cells where a factor has different signs"
        return ""

    # -- storage ------------------------------------------------------------------

    def payload(self) -> dict:
        return {"variables": list(self.variables),
                "levels": [[format_polynomial(p) for p in level] for level in self.levels],
                "factors": [format_polynomial(p) for p in self.factors],
                "cells": [[list(index), n] for index, n in sorted(self.numbers.items())]}

    @classmethod
    def from_payload(cls, payload: dict) -> RegionMap:
        variables = tuple(payload["variables"])
        ctx = fmpq_mpoly_ctx.get(variables, "lex")
        return cls(variables,
                   tuple(tuple(parse_polynomial(t, ctx) for t in level)
                         for level in payload["levels"]),
                   tuple(parse_polynomial(t, ctx) for t in payload["factors"]),
                   {tuple(int(i) for i in index): int(n) for index, n in payload["cells"]})


class RegionMapCache:
    """Region maps on disk, one JSON file per (variety, slice)."""

    def __init__(self, directory: Path | None = None) -> None:
        from singcheck.elimination.cache import cache_dir

        self.directory = (directory or cache_dir()) / "regions"

    @staticmethod
    def key(polynomials, fixed: dict[str, Fraction]) -> str:
        from singcheck.elimination.cache import _digest

        return _digest(REGIONS_VERSION, *(f"{k}={v}" for k, v in sorted(fixed.items())),
                       *sorted(format_polynomial(p) for p in polynomials))

    def _path(self, key: str) -> Path:
        return self.directory / f"{key}.json"

    def load(self, key: str) -> RegionMap | None:
        from singcheck.elimination.cache import read_entry

        try:
            return RegionMap.from_payload(read_entry(self._path(key), FORMAT, key))
        except (OSError, ValueError, KeyError, TypeError, PolynomialSyntaxError,
                RecursionError):
            return None

    def store(self, key: str, region_map: RegionMap) -> None:
        from singcheck.elimination.cache import write_entry

        write_entry(self._path(key), FORMAT, key, region_map.payload())
