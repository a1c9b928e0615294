"""Robot and trajectory spec files (stage 2): untrusted YAML read exactly.

``grammar`` is singcheck's own expression language (no eval, no sympify; numbers are
exact rationals); ``files`` reads robot and trajectory YAML through its node tree, so
every error names the file and line; ``trajectory`` is the trajectory spec (one piece,
rescaled for sin/cos of k·π·t) and ``paths`` the multi-piece forms (segments, waypoints,
natural cubic splines, CSV tables) with their exact joins.  May import ``algebra`` only.
"""
