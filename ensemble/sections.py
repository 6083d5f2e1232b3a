"""The top-level tables of a run config, by name.

config.py gives each section its dataclass; filekind.py knows a TOML file for a config by these
names. Both import them from here, so neither imports the other for them (config.py reads files
through filekind.py).
"""
SECTION_NAMES = ("model", "run", "integrator", "output")
SWEEP = "sweep"     # the table of swept values, beside the sections
POPULATION = "population"   # the table of a population's draws (ensemble/population.py)
