"""The work of a grain's step, which the ranks balance (DESIGN.md section 7).

A step's cost is modelled as a sum over nodes, intact bond copies (two per bond) and contact
list entries (node pairs, both ways, and wall surfaces):

    work = n + BOND_COPY c + LIST_ENTRY e        [in nodes' work]

A node's integration, dilatation and surface point; a bond copy's force; an entry's distance
test and, in contact, its force. The weights come from serial runs on one thread
(benchmarks/work_weights.py, which fits T = a n + b c + d e over its cases):
- a bond copy: 0.06 of a node in 2D (the pile's grains far apart against fine2d and fine2d
  with a horizon of 4.5 mesh sizes), 0.08-0.11 in 3D (two runs);
- an entry: 1.0 of a node's work where the grains rest barely apart (listed, not pressed:
  4.2 against 6.4 ms a step for 32,000 nodes and 37,474 entries), 1.9 in a pressed pile, more
  where grains shatter (breaking bonds cost more than their count says); in 3D 0.9-1.8 (two
  runs of the fit: pile3d and spheres pressed 1.95-1.97 R apart). 1.5 is taken in both. On
  2 ranks (benchmarks/work_balance.py) an entry of grains at rest cost 1.1.
Between cases a fit of these three counts misses by up to 34 %; within a run, where the grains
share a law and a mesh, it is the counts that differ. The counts are the run's own, not
timings: the same ranks find the same work every run, and cut alike.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Work of an intact bond copy, per dimension, and of a contact list entry, in nodes' work.
BOND_COPY = {2: 0.06, 3: 0.11}
LIST_ENTRY = 1.5


def node_work(core: Any, nodes: NDArray[np.int64], dimension: int) -> NDArray[np.float64]:
    """Per node of `nodes` (local to `core`): 1 + BOND_COPY c + LIST_ENTRY e, c its intact
    bond copies and e its entries in the contact lists of their last build."""
    local = np.ascontiguousarray(nodes, dtype=np.int64)
    copies = np.asarray(core.intact_bond_copies(local), dtype=np.float64)
    entries = np.asarray(core.contact_list_entries(local), dtype=np.float64)
    return 1.0 + BOND_COPY[dimension] * copies + LIST_ENTRY * entries


def imbalance(loads: NDArray[np.float64]) -> float:
    """The largest of the ranks' `loads` over their mean (1: balanced)."""
    return float(loads.max() / loads.mean())
