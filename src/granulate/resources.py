"""Memory a set-up will need, estimated before anything large is allocated, against what the
machine has free: a mesh size far too small, a packing of a billion grains or a horizon of many
mesh sizes is refused with the figure, instead of allocating until MemoryError (or the machine
swaps)."""

from __future__ import annotations

import math
import os
from pathlib import Path

from granulate.errors import InputError

#: Core bytes per node besides its bonds (state, reference, constants, contact lists; the
#: measured 260-300 of ARCHITECTURE.md, rounded up).
BYTES_PER_NODE = 320
#: Bytes per bond of a bond family (neighbour, length, weight).
BYTES_PER_BOND = 16
#: The share of the free memory a set-up may plan to use.
SHARE = 0.8


def available_memory() -> int:
    """Bytes the machine has free now (MemAvailable; the physical pages free elsewhere)."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 8 * 2**30


def size_text(count: float) -> str:
    """Bytes for people: 3.2 GB, 450 MB, 1.1 TB."""
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if count >= scale:
            return f"{count / scale:.3g} {unit}"
    return f"{count / 1e3:.3g} kB"


def require_memory(needed: float, what: str, fix: str) -> None:
    """InputError when `what` needs more than SHARE of the free memory, naming both and `fix`."""
    free = available_memory()
    if not needed <= SHARE * free:
        raise InputError(
            f"{what} would need about {size_text(needed)} of memory, more than this machine has "
            f"free ({size_text(free)}); {fix}"
        )


def bonds_per_node(dimension: int, horizon_factor: float) -> float:
    """Neighbours within a horizon of delta = factor h on a lattice of spacing h: the disc
    (ball) of radius factor, pi f^2 (4/3 pi f^3)."""
    if dimension == 2:
        return math.pi * horizon_factor**2
    return 4.0 / 3.0 * math.pi * horizon_factor**3


def simulation_bytes(nodes: float, bonds: float) -> float:
    """The core's memory for `nodes` nodes and `bonds` bonds in their families."""
    return BYTES_PER_NODE * nodes + BYTES_PER_BOND * bonds


#: Seconds to place one grain of a random packing and add it as a particle: measured with
#: benchmarks/packing.py (10,000 and 40,000 grains: 0.2-0.25 ms in 2D at 43 % of the area,
#: 0.75-0.85 ms in 3D at 30 % of the volume), rounded up. Denser packings take longer.
SETUP_SECONDS_PER_GRAIN = {2: 3e-4, 3: 1e-3}


def setup_seconds(dimension: int, grains: int) -> float:
    """About how long packing `grains` grains and adding them as particles takes [s]."""
    return SETUP_SECONDS_PER_GRAIN[dimension] * grains
