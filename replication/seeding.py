"""Seeds keyed by a run's identity, never by its position in a job list."""

import hashlib

import numpy as np


def stable_key(text: str) -> int:
    """A 32-bit integer from ``text`` that is the same on every machine and Python run."""
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:4], "little")


def seed_sequence(base_seed: int, *identity: str | int) -> np.random.SeedSequence:
    """The child of ``SeedSequence(base_seed)`` at spawn key ``identity``.

    Equivalent to walking ``SeedSequence(base_seed).spawn`` down the path given
    by the identity, so runs are statistically independent and a run's stream
    does not depend on how many jobs run or in which order.
    """
    key = tuple(part if isinstance(part, int) else stable_key(part) for part in identity)
    return np.random.SeedSequence(base_seed, spawn_key=key)
