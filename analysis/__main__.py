import sys

from ensemble.pipes import exit_quietly_on_closed_stdout

from .cli import main

sys.exit(exit_quietly_on_closed_stdout(main))
