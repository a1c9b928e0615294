"""Robot and trajectory spec files (stage 2): untrusted YAML read exactly.

``grammar`` is singcheck's own expression language (no eval, no sympify; numbers are
exact rationals); ``files`` reads robot and trajectory YAML through its node tree, so
every error names the file and line.  May import ``algebra`` only.
"""
