"""Code that runs inside the computer-algebra systems (shipped as package data).

``singcheck.lib`` is a Singular library, ``singcheck.m2`` a Macaulay2 file; the scripts
singcheck generates load them.  Installed as the package ``singcheck.cas_library``.
"""
