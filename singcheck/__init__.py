"""singcheck: certify that a parallel robot's trajectory avoids parallel singularities.

The method is Jha, Chablat, Rouillier, Moroz, "An algebraic method to check the
singularity-free paths for parallel robots" (IDETC 2015).
"""

__version__ = "0.1.0"
