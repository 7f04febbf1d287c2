"""Write stage 2 of PeriDEM's n500_circ_hex (its run2, made by its problem_setup.py; the deck's
README): a copy of the stage-1 deck that restarts from stage 1's last frame (step 600,000,
t = 0.06 s), runs to Final_Time 0.15 s at dt 1e-7 s, with the moving wall's zone re-placed as
PeriDEM's run2 does ([-0.22, 34.82] to [68.72, 35.42] mm) and its mesh moved down 6.4 mm.

    python docs/validation/peridem_stage2.py STAGE1_DECK_FOLDER FRAME.vtu STAGE2_FOLDER

The commands of the whole run: examples/compression_2d/README.md.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import yaml

WALL_SHIFT = -6.4e-3  # m, the moving wall's mesh, as PeriDEM's mw_dy1 places its zone
WALL_ZONE = [-2.2e-4, 3.482e-2, 0.0, 6.872e-2, 3.542e-2, 0.0]  # m, Zone_4 in run2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("stage1", type=Path, help="the stage-1 deck's folder (input_0.yaml)")
    parser.add_argument("frame", type=Path, help="stage 1's last frame (frames/frame_NNNNNN.vtu)")
    parser.add_argument("stage2", type=Path, help="the folder to write (replaced)")
    args = parser.parse_args()
    shutil.rmtree(args.stage2, ignore_errors=True)
    shutil.copytree(args.stage1, args.stage2)
    deck_file = args.stage2 / "input_0.yaml"
    deck = yaml.safe_load(deck_file.read_text())
    deck["Model"]["Final_Time"] = 0.15
    deck["Model"]["Time_Steps"] = 1_500_000
    deck["Zone"]["Zone_4"]["Parameters"] = WALL_ZONE
    deck["Restart"] = {"File": str(args.frame.resolve()), "Step": 600_000}
    deck_file.write_text(yaml.safe_dump(deck, sort_keys=False))
    moved = shift_mesh(args.stage2 / "mesh_moving_wall_0.msh", WALL_SHIFT)
    print(f"wrote {deck_file}; moved {moved} wall nodes by {WALL_SHIFT * 1e3} mm")


def shift_mesh(mesh: Path, dy: float) -> int:
    """Move the nodes of a Gmsh 2 mesh by dy in y; returns their number."""
    lines = mesh.read_text().splitlines()
    start = lines.index("$Nodes")
    count = int(lines[start + 1])
    for i in range(start + 2, start + 2 + count):
        k, x, y, z = lines[i].split()
        lines[i] = f"{k} {x} {float(y) + dy!r} {z}"
    mesh.write_text("\n".join(lines) + "\n")
    return count


if __name__ == "__main__":
    main()
