"""Named, independent random streams derived from one scenario seed.

Every component draws from its own stream keyed by a name path (``"imu", "gyro"`` or ``"gnss", "ant0", "G05"``).
The key is a stable hash of the names (not a spawn counter), so adding or removing a component never changes
another component's noise, and the same seed and names always give bit-identical draws.
"""
from __future__ import annotations

import hashlib

import numpy as np


def _name_key(name: str) -> int:
    return int.from_bytes(hashlib.blake2b(name.encode(), digest_size=4).digest(), "little")


def seed_sequence(seed: int, *names: str) -> np.random.SeedSequence:
    """The SeedSequence of the stream ``names`` under scenario ``seed``."""
    return np.random.SeedSequence(int(seed), spawn_key=tuple(_name_key(n) for n in names))


def generator(seed: int, *names: str) -> np.random.Generator:
    """A PCG64 generator for the stream ``names`` under scenario ``seed``."""
    return np.random.Generator(np.random.PCG64(seed_sequence(seed, *names)))
