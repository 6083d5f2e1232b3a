import sys

from .cli import main
from .pipes import exit_quietly_on_closed_stdout

sys.exit(exit_quietly_on_closed_stdout(main))
