"""The polynomial model of a robot (stage 3): F(ρ, X) = 0, A = ∂F/∂X, B = ∂F/∂ρ, det A
and det B, and each leg's inverse-kinematics structure.  May import ``spec`` and
``algebra``.
"""
