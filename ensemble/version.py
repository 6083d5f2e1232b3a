"""The package's version, in a module of its own: its modules read it here, not from the package, which would make
an import circle with the front door the package exposes (api.py)."""
__version__ = "0.1.0"
