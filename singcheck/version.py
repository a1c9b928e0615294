"""The version of singcheck (a foundation module: it imports nothing)."""

__version__ = "0.1.0"
