"""How the wall speed changes a compression's load curve: the compression example's pile
(examples/compression_2d: 120 discs and hexagons settled to rest in a 33 mm wide container) is
settled once and compressed from that state at several wall speeds, 3.4 mm each; the top
wall's stress against its travel for each speed, with the inertial number of each.

The inertial number I = (strain rate) d sqrt(rho / p), strain rate = v / H (H the settled pile's
height), d = 2 mm, rho = 1200 kg/m^3, p the wall stress at the end of the run, is the usual
measure of how quasi-static a granular flow is (GDR MiDi 2004: below about 1e-3).

Run: python docs/validation/loading_rate.py [--out DIR] [--speeds 1.2 0.6 ...]; writes
docs/validation/loading_rate.png and prints the table (stress at 1.0, 1.6, 2.0, 2.4 and 3.4 mm,
kinetic energy at the end over the wall's work, I). 15 minutes on one thread here.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import granulate as gr

sys.path.insert(0, str(Path(__file__).parents[2] / "examples" / "compression_2d"))
import compression_2d  # the example's packing, settling and compression stages

GRAINS, TRAVEL = 120, 3.4e-3
TRAVELS = (1.0, 1.6, 2.0, 2.4, 3.4)  # where the table reads the stress [mm]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/loading_rate", help="output directory")
    parser.add_argument(
        "--speeds", type=float, nargs="+", default=[1.2, 0.6, 0.3, 0.15, 0.06], help="[m/s]"
    )
    args = parser.parse_args()
    out = Path(args.out)
    width = compression_2d.WIDTH * min(1.0, math.sqrt(GRAINS / 502))
    grains = compression_2d.packing(GRAINS, width, seed=1)
    settled, bodies = compression_2d.settle(grains, width, 1.0, out / "settle", True)
    height = float(settled.positions[:, 1].max())
    curves = {}
    for speed in args.speeds:
        folder = out / f"compress_{speed:g}"
        sim = compression_2d.compress(
            grains, width, settled, bodies, speed, TRAVEL, folder, overwrite=True
        )
        history = gr.Results(folder).history
        curves[speed] = history
        travel = 1e3 * np.abs(history["top_displacement"])
        stress = history["top_stress"]
        at = [1e-3 * float(np.interp(x, travel, stress)) for x in TRAVELS]
        work = float(np.sum(np.diff(np.abs(history["top_displacement"])) * stress[1:])) * width
        inertial = inertial_number(speed, height, float(stress[-1]))
        print(
            f"{speed:5.2f} m/s, {sim.summary()['steps']:6d} steps: stress "
            + " / ".join(f"{s:5.1f}" for s in at)
            + f" kPa at {' / '.join(map(str, TRAVELS))} mm; kinetic energy / wall work "
            f"{float(history['kinetic_energy'][-1]) / work:.3f}; I = {inertial:.2g}"
        )
    plot(curves, height, Path(__file__).with_name("loading_rate.png"))


def inertial_number(speed: float, height: float, stress: float) -> float:
    """I = (v / H) d sqrt(rho / p): d = 2 mm, rho = 1200 kg/m^3, p = `stress` [Pa] (at least
    1 Pa), H = `height` [m]."""
    return speed / height * 2e-3 * math.sqrt(1200 / max(stress, 1.0))


def plot(curves: dict[float, dict[str, np.ndarray]], height: float, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for speed, history in curves.items():
        stress = history["top_stress"]
        inertial = inertial_number(speed, height, float(stress[-1]))
        ax.plot(
            1e3 * np.abs(history["top_displacement"]),
            1e-3 * stress,
            label=f"{speed:g} m/s (I = {inertial:.1g})",
        )
    ax.set_xlabel("wall travel [mm]")
    ax.set_ylabel("top wall stress [kPa]")
    ax.legend(fontsize=8, title="wall speed", title_fontsize=8)
    fig.suptitle(f"One settled pile ({GRAINS} grains) compressed at five wall speeds", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
