"""A run's outputs: Outputs (outputs.py) decides which steps write a frame and a history row;
the registered writers (registry.py) write them from one StepData per step (step_data.py):

- frame writers (base.FrameWriter): the VTU frame and simulation.pvd (vtu_frame.py), the
  particle table (particle_tables.py), the fragment table (fragment_tables.py) and the contact
  network (contact_network.py);
- history sections (base.HistorySection, history_sections.py): energies and counts, breakage,
  granular measures, wall loads, tracked bodies.

To add an output, write one small class with ``write(data, outputs)`` (a frame writer) or
``columns(data, outputs)`` (history columns) and register it (registry.py).
"""

from granulate.writers.base import FrameWriter, HistorySection
from granulate.writers.outputs import Outputs
from granulate.writers.registry import (
    FRAME_WRITERS,
    HISTORY_SECTIONS,
    register_frame_writer,
    register_history_section,
)
from granulate.writers.step_data import StepData

__all__ = [
    "FRAME_WRITERS",
    "HISTORY_SECTIONS",
    "FrameWriter",
    "HistorySection",
    "Outputs",
    "StepData",
    "register_frame_writer",
    "register_history_section",
]
