"""Exact and interval arithmetic shared by every stage (stage 1, the bottom).

Balls around exact polynomials (``intervals``), polynomial helpers over Q
(``polynomials``), and trajectories made algebraic: polynomials in t, s = sin t and
c = cos t with s² + c² = 1 (``trig``).  Imports nothing of singcheck but the
foundation modules (``errors``, ``budget``).
"""
