"""The contact network of a frame: frames/contacts_NNNNNN.csv (granulate.network), the force
chains frames/contacts_NNNNNN.vtu (a line from each body's centre to the other's, or to the
contact point on a wall) and contacts.pvd, whose entries follow simulation.pvd's."""

from __future__ import annotations

from pathlib import PurePosixPath
from typing import TYPE_CHECKING

from granulate import network
from granulate.io import PvdSeries, write_vtu

if TYPE_CHECKING:
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData


class ContactNetwork:
    needs_whole_state = False  # reads StepData's values (base.py)

    def write(self, data: StepData, outputs: Outputs) -> None:
        frames, frame = outputs.directory / "frames", outputs.frames
        network.write_table(frames / f"contacts_{frame:06d}.csv", data.contacts)
        points, cells = network.chain_lines(data.contacts, data.fragments)
        write_vtu(
            frames / f"contacts_{frame:06d}.vtu",
            points,
            {},
            lines=cells,
            cell_data=network.chain_fields(data.contacts),
        )
        chains = PvdSeries(outputs.directory / "contacts.pvd")
        for t, name in outputs.pvd.entries:  # frames/frame_NNNNNN.vtu, or .pvtu (pieces)
            chain = PurePosixPath(name.replace("/frame_", "/contacts_")).with_suffix(".vtu")
            chains.entries.append((t, str(chain)))
        chains.write()
