"""The undo log of the event in progress: the between-events state while an event is paused.

A checkpoint may only hold a between-events state, but a kernel call can stop in the middle of
an event (chain.simulate's work budget). An event changes only the blocks it materializes or
slides, so before it first changes a block (the epicenter brought to its onset, a block watched
or started, schedule.py and event.py) the block's between-events values (F0, P, since) go into
the log, once: O(blocks the event touches). Workspace.between_events applies the log to copies;
the log is emptied when the event has finished.
"""
import numba as nb

from .workspace import EV_NUNDO, F0, LOGGED, P, U_BLOCK, U_F0, U_P, U_SINCE_HI, U_SINCE_LO


@nb.njit(cache=True)
def log_block(W, since, event, undo, j):
    """Keep block j's between-events values, unless this event has already kept them."""
    if W[j, LOGGED] != 0.0:
        return
    W[j, LOGGED] = 1.0
    row = int(event[EV_NUNDO])
    undo[row, U_BLOCK] = j
    undo[row, U_F0] = W[j, F0]
    undo[row, U_P] = W[j, P]
    undo[row, U_SINCE_HI] = since[j, 0]
    undo[row, U_SINCE_LO] = since[j, 1]
    event[EV_NUNDO] = row + 1


@nb.njit(cache=True)
def clear_log(W, event, undo):
    """The event has finished: its state is the between-events state, the log is empty."""
    for row in range(int(event[EV_NUNDO])):
        W[int(undo[row, U_BLOCK]), LOGGED] = 0.0
    event[EV_NUNDO] = 0.0
