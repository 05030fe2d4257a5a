"""Errors a user can fix, and how the command lines report them: one line on stderr, exit status 2."""

import sys


class ConfigError(ValueError):
    """A config that cannot run; the message is meant for the user as is."""


def fail(message: str) -> None:
    print(f"error: {message}", file=sys.stderr)
    raise SystemExit(2)


class RunFailed(ValueError):
    """A run that cannot give a record: it fails with this reason, which is stored
    (:mod:`replication.runner.failures`), rather than stopping the command."""


class NotFinite(RunFailed):
    """A number a run needs is NaN or infinite (log-weights, say)."""
