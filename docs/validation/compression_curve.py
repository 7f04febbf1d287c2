"""The top wall's stress against its travel in the native compression workflow
(examples/compression_2d/compression_2d.py: pack, settle to rest, place the wall on the pile,
compress), on the axes of the PeriDEM paper's Fig. 3a (Jha et al., JMPS 2021), whose curve is
drawn from the numbers read off the published figure
(../shared/peridem/decks/n500_circ_hex/README.md).

This is not yet the reproduction: the paper compresses 502 grains at 0.06 m/s (1.5 million
steps of 63,000 nodes, about 44 hours in PeriDEM here); the run drawn is the example's default,
fewer grains in a narrower container at ten times the speed, so the onset (where the wall
meets the pile) and the level differ. It shows the workflow's load curve and what a user's
figure looks like.

Run: python examples/compression_2d/compression_2d.py --out out/compression, then
python docs/validation/compression_curve.py out/compression; writes
examples/compression_2d/compression_curve.png.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import granulate as gr

FIGURE = Path(__file__).parents[2] / "examples" / "compression_2d" / "compression_curve.png"

# Fig. 3a of the paper, read off the published figure: wall penetration [mm], stress [kPa].
PAPER = np.array(
    [
        (0.0, 0.0), (0.4, 0.5), (0.5, 3), (0.6, 6), (0.7, 12), (0.8, 19), (1.0, 29), (1.2, 38),
        (1.45, 56), (1.6, 62), (1.85, 80), (1.95, 76), (2.1, 80), (2.4, 87), (2.7, 89),
        (3.0, 92), (3.3, 85),
    ]
)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="the example's --out folder (holding compress/)")
    args = parser.parse_args()
    run = Path(args.run)
    results = gr.Results(run / "compress")
    history = results.history
    summary = json.loads((run / "compress" / "run.json").read_text())
    grains = summary["bodies"]
    speed = float(history["top_displacement"][-1] / history["time"][-1])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(
        1e3 * np.abs(history["top_displacement"]),
        1e-3 * history["top_stress"],
        "-",
        label=f"granulate, native workflow: {grains} grains, wall at {speed:.2g} m/s",
    )
    ax.plot(
        PAPER[:, 0],
        PAPER[:, 1],
        "o--",
        ms=4,
        label="Jha et al. 2021, Fig. 3a (502 grains, 0.06 m/s)",
    )
    ax.set_xlabel("wall travel (penetration) [mm]")
    ax.set_ylabel("top wall stress: force per unit area [kPa]")
    ax.legend(fontsize=8)
    print(
        f"{grains} grains, wall at {speed:.3g} m/s: stress {1e-3 * history['top_stress'][-1]:.3g}"
        f" kPa after {1e3 * abs(history['top_displacement'][-1]):.2f} mm, broken bonds "
        f"{int(history['broken_bonds'][-1])}"
    )
    fig.suptitle("Compression of discs and hexagons: the top wall's stress", fontsize=9)
    fig.tight_layout()
    out = FIGURE
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
