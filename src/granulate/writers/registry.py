"""The writers every run's outputs use, in the order they write: add one by writing a small
class (base.FrameWriter or base.HistorySection) in its own file and registering it here, or,
from outside the package, with register_frame_writer / register_history_section."""

from __future__ import annotations

from granulate.writers.base import FrameWriter, HistorySection
from granulate.writers.contact_network import ContactNetwork
from granulate.writers.fragment_tables import FragmentTables
from granulate.writers.history_sections import (
    Breakage,
    Energies,
    GranularMeasures,
    TrackedBodies,
    WallLoads,
)
from granulate.writers.particle_tables import ParticleTables
from granulate.writers.vtu_frame import VtuFrame

#: Each frame's files, in order (the contact network's PVD follows the VTU frame's).
FRAME_WRITERS: list[FrameWriter] = [
    VtuFrame(),
    ParticleTables(),
    FragmentTables(),
    ContactNetwork(),
]
#: A history.csv row's sections, in column order.
HISTORY_SECTIONS: list[HistorySection] = [
    Energies(),
    Breakage(),
    GranularMeasures(),
    WallLoads(),
    TrackedBodies(),
]


def reads_values_only() -> bool:
    """Whether every registered writer and section reads StepData's values alone (its class
    sets needs_whole_state = False, base.py): then a distributed run's step data made of its
    ranks' measures, which has no simulation, serves them all."""
    writers = [*FRAME_WRITERS, *HISTORY_SECTIONS]
    return not any(getattr(writer, "needs_whole_state", True) for writer in writers)


def register_frame_writer(writer: FrameWriter) -> None:
    """Every run's frames from now on also call ``writer.write``."""
    FRAME_WRITERS.append(writer)


def register_history_section(section: HistorySection) -> None:
    """Every history.csv started from now on also has ``section``'s columns (after the
    others; a file already started keeps its columns)."""
    HISTORY_SECTIONS.append(section)
