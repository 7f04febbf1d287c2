"""Sums over nodes, contacts or pieces in an order that does not depend on the thread count.

NumPy's ``@`` hands long dot products to BLAS, which splits them among its threads (as many as
OMP_NUM_THREADS says) and so rounds differently for each count: a run's history.csv would
change in its last digits with the thread count. These use NumPy's own single-threaded loops.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def _floats(a: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(a, dtype=np.float64)


def dot(a: ArrayLike, b: ArrayLike) -> float:
    """sum_i a_i b_i."""
    return float(np.einsum("i,i->", _floats(a), _floats(b)))


def weighted_sum(weights: ArrayLike, rows: ArrayLike) -> NDArray[np.float64]:
    """sum_i w_i x_i for the rows x_i of an (n, d) array."""
    return np.einsum("i,ij->j", _floats(weights), _floats(rows))


def outer_sum(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """sum_k a_k b_k^T for the rows of two (n, d) arrays: the (d, d) matrix a^T b."""
    return np.einsum("ki,kj->ij", _floats(a), _floats(b))
