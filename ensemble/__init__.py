"""MPI-parallel ensemble runner for the Burridge-Knopoff chain with rate- and state-dependent friction."""
__version__ = "0.1.0"
