"""Workspace and joint-space analysis (stage 7): the discriminant variety, an open CAD
of its complement over Q, exact solution counts, connected regions, and where a path
lies among them.

``cad`` decomposes, ``solution_counts`` counts, ``segments``/``regions``/
``plane_adjacency`` join cells into proven regions, ``analysis`` drives it,
``region_map``/``path_regions`` place a trajectory.  May import every stage below
(``certify`` and down).
"""
