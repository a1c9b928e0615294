"""Projection by elimination (stage 4): ξ(X), the workspace boundary and the joint
limits projected into the workspace.

``requests`` says what the core asks (plain data), ``projection`` asks it and re-checks
ξ in-process, ``cas/`` holds one adapter per engine (Singular and Macaulay2 as
processes, SymPy and FLINT in-process), ``cache`` keeps verified results on disk.
May import ``model``, ``spec`` and ``algebra``.
"""
