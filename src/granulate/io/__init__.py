"""Reading and writing: VTU frames with a PVD series, history CSV, atomic file writes."""

from granulate.io.atomic import atomic_write
from granulate.io.history import HistoryWriter
from granulate.io.vtu import PvdSeries, write_vtu

__all__ = ["HistoryWriter", "PvdSeries", "atomic_write", "write_vtu"]
