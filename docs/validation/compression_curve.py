"""The top wall's stress against its travel in the native compression workflow
(examples/compression_2d/compression_2d.py: pack, settle to rest, place the wall on the pile,
compress), on the axes of the PeriDEM paper's Fig. 3a (Jha et al., JMPS 2021), whose curve is
drawn from the numbers read off the published figure
(../shared/peridem/decks/n500_circ_hex/README.md).

compression_curve.png draws the example's default run: 120 grains in a narrower container at
ten times the paper's speed. fig3a.png draws the paper's size and rate, 502 grains at
0.06 m/s, natively and with PeriDEM's 2D constants (the commands and what differs from the
paper: examples/compression_2d/README.md).

Run: python examples/compression_2d/compression_2d.py --out out/compression, then
python docs/validation/compression_curve.py out/compression; writes
examples/compression_2d/compression_curve.png. Several runs draw several curves (``--labels``
names them); ``--snapshots NAME ...`` also writes, per run, examples/compression_2d/NAME: the
nodes coloured by damage at the paper's four instants, wall travels of 0.5, 1.45, 1.95 and
2.4 mm (the frames nearest them); ``--figure NAME`` writes the curve under another name.

A run may also be the output folder of a PeriDEM deck's compression (n500_circ_hex's stage 2,
run with --peridem-compat; the deck's README): its loaded wall's history columns (pNNN_stress,
pNNN_uy) give the curve, the travel counted from the run's first row, where the restart placed
the wall above the settled pile.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import granulate as gr

FOLDER = Path(__file__).parents[2] / "examples" / "compression_2d"
#: The paper's damage snapshots t1 ... t4 (its Fig. 3): wall travel [mm].
INSTANTS = (0.5, 1.45, 1.95, 2.4)

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
    parser.add_argument("runs", nargs="+", help="the example's --out folders (holding compress/)")
    parser.add_argument("--labels", nargs="+", help="one per run (default: grains and speed)")
    parser.add_argument("--figure", default="compression_curve.png", help="the curve's file name")
    parser.add_argument(
        "--snapshots", nargs="+", help="file names of the damage snapshots, one per run"
    )
    args = parser.parse_args()
    for given, what in ((args.labels, "--labels"), (args.snapshots, "--snapshots")):
        if given is not None and len(given) != len(args.runs):
            parser.error(f"give one name in {what} per run")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for k, run in enumerate(map(Path, args.runs)):
        curve = load_curve(run)
        results, history, speed, grains = curve.results, curve.history, curve.speed, curve.grains
        label = args.labels[k] if args.labels else f"{grains} grains, wall at {speed:.2g} m/s"
        travel, stress = curve.travel, curve.stress
        ax.plot(travel, 1e-3 * stress, "-", label=f"granulate: {label}")
        print(
            f"{run}: {grains} grains, wall at {speed:.3g} m/s: stress "
            + ", ".join(f"{1e-3 * np.interp(x, travel, stress):.1f}" for x in PAPER[5:, 0])
            + f" kPa at {', '.join(f'{x:g}' for x in PAPER[5:, 0])} mm; broken bonds "
            f"{int(history['broken_bonds'][-1])}"
        )
        if args.snapshots:
            draw_snapshots(results, speed, curve.start, FOLDER / args.snapshots[k])
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
    fig.suptitle("Compression of discs and hexagons: the top wall's stress", fontsize=9)
    fig.tight_layout()
    out = FOLDER / args.figure
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


@dataclass
class Curve:
    """A compression run's load curve: wall travel [mm] and stress [Pa] per history row."""

    results: gr.Results
    history: dict[str, np.ndarray]  # history.csv, read once
    travel: np.ndarray
    stress: np.ndarray
    speed: float  # the wall's [m/s]
    start: float  # time at zero travel [s]
    grains: int


def load_curve(run: Path) -> Curve:
    """The example's folder (its compress/ run: top_displacement, top_stress) or a deck's
    (the loaded wall's pNNN_uy and pNNN_stress, travel from the first row)."""
    if (run / "compress").is_dir():
        results = gr.Results(run / "compress")
        history = results.history
        travel = 1e3 * np.abs(history["top_displacement"])
        stress, start = history["top_stress"], 0.0
    else:
        results = gr.Results(run)
        history = results.history
        stressed = [name for name in history if name.endswith("_stress") and name[0] == "p"]
        if len(stressed) != 1:
            raise SystemExit(f"{run}: neither compress/ nor one loaded wall's _stress column")
        wall = stressed[0].removesuffix("_stress")
        travel = 1e3 * np.abs(history[f"{wall}_uy"] - history[f"{wall}_uy"][0])
        stress, start = history[stressed[0]], float(history["time"][0])
    speed = float(1e-3 * travel[-1] / (history["time"][-1] - start))
    bodies = json.loads((results.directory / "run.json").read_text())["bodies"]
    walls = [name for name in history if name[0] == "p" and name.endswith("_fx")]  # a deck's
    return Curve(results, history, travel, stress, speed, start, bodies - len(walls))


def draw_snapshots(results: gr.Results, speed: float, start: float, out: Path) -> None:
    """Four panels: the nodes coloured by damage at the frames nearest the paper's instants."""
    import matplotlib.pyplot as plt

    frames = [results.frame(time=start + 1e-3 * travel / speed) for travel in INSTANTS]
    span = np.ptp(frames[0].positions[:, :2], axis=0)
    height = 2 * 4.5 * span[1] / span[0] + 1.2  # two rows of panels 4.5 inches wide
    fig, axes = plt.subplots(
        2, 2, figsize=(10, height), sharex=True, sharey=True, layout="constrained"
    )
    for ax, travel, frame in zip(axes.flat, INSTANTS, frames, strict=True):
        points = 1e3 * frame.positions
        shown = ax.scatter(
            points[:, 0], points[:, 1], c=frame["Damage"], s=0.3, cmap="inferno_r", vmin=0, vmax=1
        )
        moved = 1e3 * speed * (frame.time - start)
        ax.set_title(f"travel {moved:.2f} mm (paper's instant: {travel} mm)", fontsize=8)
        ax.set_aspect("equal")
    for ax in axes[-1]:
        ax.set_xlabel("x [mm]")
    for ax in axes[:, 0]:
        ax.set_ylabel("y [mm]")
    fig.colorbar(shown, ax=axes, label="damage")
    fig.suptitle("Damage at the PeriDEM paper's four instants (its Fig. 3)", fontsize=9)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
