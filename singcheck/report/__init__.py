"""Rendering (stage 8): tables, JSON, formulas, figures and progress for people.

The only importer of rich and matplotlib (both lazily).  May import every stage below;
nothing below imports it.
"""
