"""Numba kernels of the Burridge-Knopoff chain with rate- and state-dependent friction.

Kernels are pure: arrays and scalars in, arrays out. Nothing here knows about
config objects, files, MPI or HDF5 (see ensemble.runner for the wrapper).
"""
