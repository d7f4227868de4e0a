"""The library's version (one place: the package, the report folder and ``linkage --version``)."""

__version__ = "0.1.0"
