"""The farm's errors: one line each, never a Dask traceback."""

from __future__ import annotations

from ..errors import WhittedError


class FarmError(WhittedError):
    """A farm option or cluster the user gave cannot be used (one line, exit status 2)."""


class ClusterLost(FarmError):
    """The cluster cannot do the job: the scheduler unreachable or lost, no worker able to
    render (every one lost, stalled, or running another whitted). One line, exit status 3;
    what the farm had finished (frames written) is kept."""
