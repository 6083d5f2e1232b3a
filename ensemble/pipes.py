"""`python -m ensemble status X | head -1` ends quietly: stdout's reader going away is no error.

Python ignores SIGPIPE, so writing to a pipe whose reader has closed raises BrokenPipeError,
inside a print or at the final flush, and ends in a traceback. The recipe of the Python docs
("Note on SIGPIPE", signal module): catch it, point stdout at /dev/null so that the flush at
exit cannot raise again, and exit.

Exit code 141 (128 + SIGPIPE), what the shell reports for any Unix filter stopped the same way
(`cat big | head -1` under `set -o pipefail`): not 0, because the output was not all delivered
and a script must not take a cut-off report for a whole one; not 1, because nothing failed.
"""
import os
import sys

EXIT_CLOSED_PIPE = 141


def exit_quietly_on_closed_stdout(main):
    """main() -> its exit code, or EXIT_CLOSED_PIPE if stdout's reader went away."""
    try:
        code = main()
        sys.stdout.flush()   # here, not at exit, where the error could only be printed
        return code
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_CLOSED_PIPE
