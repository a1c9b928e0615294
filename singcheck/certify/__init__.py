"""Certification of one trajectory (stage 6): the robot along the path, its working
modes, the candidates classified per mode, and the verdict.

``path`` composes the model and ξ with X = φ(t); ``working_modes`` finds the feasible
inverse-kinematics branches, with proofs; ``classification`` decides each candidate per
mode and gives the verdict; ``pieces`` certifies a path of several pieces (segments,
waypoints, splines, rescaled time) piece by piece and composes the answer.  May import
``roots``, ``elimination``, ``model``, ``spec`` and ``algebra``.
"""
