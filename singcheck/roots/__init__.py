"""Certified real roots (stage 5): every root of a trig polynomial on a time range in a
ball proven to hold exactly one, every gap proven root-free, the rest ``Undecided``.

``rational`` isolates roots of univariate polynomials over Q exactly (Descartes
bisection); ``half_angle`` maps sin/cos paths to Q[u] with u = tan(t/2);
``branch_bound`` handles paths mixing t with sin t and cos t, ``transcendental`` tests
exactly whether a trig polynomial vanishes at one of their roots; ``isolation`` dispatches;
``enclosures`` holds the result types.  May import ``algebra`` only.
"""
