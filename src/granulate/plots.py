"""Plots and renders of a run directory, without ParaView (matplotlib, Agg backend).

``plot_history(directory)`` writes from history.csv:
- ``energies.png``: kinetic, strain and contact-spring energy against time, and the change of
  the gravitational and total energy (their sum) since the start;
- ``broken_bonds.png``: broken bonds against time;
- ``wall_<name>.png`` for every wall: the force components against the wall's displacement
  (a compression test's load curve), and ``wall_<name>_stress.png`` for a wall given an area:
  its stress [kPa] against its displacement [mm];
- ``body_<name>_stress.png`` likewise for a tracked body given an area (``track_areas``; a
  PeriDEM deck's compressive-test wall), against its mean displacement along its main motion;
- ``coordination.png``: the mean coordination number and the particle pairs in contact
  against time;
and from the fragment tables of the frames (``frames/fragments_NNNNNN.csv``):
- ``grading.png``: grading curves (mass fraction passing against equivalent diameter, log
  axis) of the first frame, the last and up to three between;
- ``breakage.png``: Hardin's relative breakage Br and t10 against the frame's time
  (granulate.fragments);
and from the last frame's contact table (``frames/contacts_NNNNNN.csv``), in 2D:
- ``force_chains.png``: a line between the centres of every two bodies in contact (and to the
  contact point on a wall), its width proportional to the normal force.

``two_scales(path, x, left, right, labels)`` draws two curves against one x axis, each on its
own y scale (the examples' figures: a load and broken bonds, damage and pieces).

``render(directory, frame=None, gif=False)`` writes ``renders/frame_NNNNNN.png``: the nodes of
each VTU frame coloured by damage (2D: in the plane; 3D: projected on x-z), and with ``gif`` an
animated ``renders/run.gif``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from granulate import fragments, network
from granulate.errors import InputError
from granulate.io.history import read_history
from granulate.io.vtu import read_vtu_point_data
from granulate.results import Results


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def two_scales(
    path: str | Path,
    x: np.ndarray,
    left: np.ndarray,
    right: np.ndarray,
    labels: tuple[str, str, str],
    *,
    right_steps: bool = False,
) -> Path:
    """Write `left` (blue, left axis) and `right` (red, right axis) against `x`, labelled
    (x, left, right); `right_steps` draws the right curve as steps with integer ticks (counts).
    Returns the path."""
    from matplotlib.ticker import MaxNLocator

    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(6, 3.5))
    axis.plot(x, left, color="C0")
    axis.set(xlabel=labels[0], ylabel=labels[1])
    axis.yaxis.label.set_color("C0")
    other = axis.twinx()
    if right_steps:
        other.step(x, right, color="C3", where="post")
        other.yaxis.set_major_locator(MaxNLocator(integer=True))
    else:
        other.plot(x, right, color="C3")
    other.set_ylabel(labels[2], color="C3")
    return _save(plt, figure, Path(path))


def _save(plt, figure, path: Path) -> Path:
    """Write a plot (tight layout, 120 dpi) and close it; returns the path."""
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def plot_history(directory: str | Path) -> list[Path]:
    """Write the history plots (see the module docstring); returns their paths."""
    history = read_history(directory)
    plt = _pyplot()
    folder = Path(directory)
    written = []
    t = history["time"]

    figure, axes = plt.subplots(figsize=(6, 4))
    for name in ("kinetic_energy", "strain_energy", "contact_energy"):
        if name in history:  # contact_energy: histories written since it exists
            axes.plot(t, history[name], label=name.replace("_", " "))
    for name in ("gravity_energy", "total_energy"):  # potentials: their change since the start
        if name in history:
            label = f"{name.replace('_', ' ')} - its start value"
            axes.plot(t, history[name] - history[name][0], label=label)
    axes.set_xlabel("time [s]")
    axes.set_ylabel("energy [J, J/m in 2D]")
    axes.legend()
    written.append(_save(plt, figure, folder / "energies.png"))

    figure, axes = plt.subplots(figsize=(6, 4))
    axes.plot(t, history["broken_bonds"])
    axes.set_xlabel("time [s]")
    axes.set_ylabel("broken bonds")
    written.append(_save(plt, figure, folder / "broken_bonds.png"))

    walls = sorted(
        {name[: -len("_displacement")] for name in history if name.endswith("_displacement")}
    )
    for wall in walls:
        figure, axes = plt.subplots(figsize=(6, 4))
        moved = history[f"{wall}_displacement"]
        for component in ("fx", "fy", "fz"):
            if f"{wall}_{component}" in history:
                axes.plot(moved, history[f"{wall}_{component}"], label=component)
        axes.set_xlabel(f"{wall} displacement [m or rad]")
        axes.set_ylabel("force on the wall [N, N/m in 2D]")
        axes.legend()
        written.append(_save(plt, figure, folder / f"wall_{wall}.png"))
        if f"{wall}_stress" in history:
            path = folder / f"wall_{wall}_stress.png"
            written.append(_stress_plot(path, wall, moved, history[f"{wall}_stress"]))
    for body in _stressed_bodies(history):
        moved = max(
            (history[f"{body}_u{a}"] for a in "xyz" if f"{body}_u{a}" in history), key=np.ptp
        )
        path = folder / f"body_{body}_stress.png"
        written.append(_stress_plot(path, body, moved, history[f"{body}_stress"]))
    if "coordination" in history:
        labels = ("time [s]", "mean coordination number Z", "particle pairs in contact")
        coordination, pairs = history["coordination"], history["contacts"]
        written.append(two_scales(folder / "coordination.png", t, coordination, pairs, labels))
    if any((folder / "frames").glob("fragments_*.csv")):
        written += plot_breakage(Results(folder))
    if any((folder / "frames").glob("contacts_*.csv")):
        written += plot_force_chains(Results(folder))
    return written


def _stressed_bodies(history: dict[str, np.ndarray]) -> list[str]:
    """Tracked bodies given an area (``<name>_stress`` beside ``<name>_ux``)."""
    names = (name[: -len("_stress")] for name in history if name.endswith("_stress"))
    return sorted(name for name in names if f"{name}_ux" in history)


def _stress_plot(path: Path, name: str, moved: np.ndarray, stress: np.ndarray) -> Path:
    """A wall's or a loaded body's stress [kPa] against its travel [mm]."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(6, 4))
    axes.plot(1e3 * np.abs(moved), 1e-3 * stress)
    axes.set_xlabel(f"{name} displacement [mm]")
    axes.set_ylabel(f"{name} stress: force per unit area [kPa]")
    return _save(plt, figure, path)


def plot_force_chains(results: Results, frame: int = -1) -> list[Path]:
    """force_chains.png of a 2D run's frame (module docstring); nothing in 3D."""
    if results.summary["dimension"] != 2:
        return []
    from matplotlib.collections import LineCollection

    plt = _pyplot()
    contacts, pieces = results.contacts(frame), results.fragments(frame)
    points, lines = network.chain_lines(contacts, pieces)
    force = np.clip(contacts["normal_force"], 0, None)
    widths = 4 * force / force.max() if len(force) and force.max() > 0 else np.ones(len(force))
    span = np.ptp(pieces["x"]), np.ptp(pieces["y"])
    height = float(np.clip(6.5 * span[1] / max(span[0], 1e-300), 2.0, 8.0)) + 1.0
    figure, axes = plt.subplots(figsize=(7, height))
    axes.add_collection(
        LineCollection(points[lines][:, :, :2], linewidths=widths, colors="tab:red")
    )
    axes.plot(pieces["x"], pieces["y"], ".", ms=2, color="0.6")
    axes.set_aspect("equal")
    axes.autoscale()
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    largest = float(force.max()) if len(force) else 0.0
    axes.set_title(f"force chains at t = {results.times[frame]:.4g} s (widest: {largest:.3g} N/m)")
    return [_save(plt, figure, results.directory / "force_chains.png")]


def plot_breakage(results: Results) -> list[Path]:
    """grading.png and breakage.png from the frames' fragment tables (module docstring). Br is
    left out when no initial piece is larger than Hardin's cut-off."""
    plt = _pyplot()
    tables = [results.fragments(k) for k in range(len(results))]
    times = results.times
    initial = tables[0]
    parent_volume = np.bincount(initial["particle"], initial["volume"])
    parent_sizes = fragments.equivalent_diameter(parent_volume, results.summary["dimension"])
    shown = sorted({0, len(tables) - 1, *np.linspace(0, len(tables) - 1, 5).astype(int)})

    figure, axes = plt.subplots(figsize=(6, 4))
    for k in shown:
        sizes, passing = fragments.grading_curve(tables[k])  # from 0 below the smallest
        axes.step(
            np.r_[sizes[0], sizes], np.r_[0, passing], where="post", label=f"t = {times[k]:.4g} s"
        )
    axes.set_xscale("log")
    axes.set_xlabel("equivalent diameter [m]")
    axes.set_ylabel("mass fraction passing [-]")
    axes.legend()
    written = [_save(plt, figure, results.directory / "grading.png")]

    figure, axes = plt.subplots(figsize=(6, 4))
    if np.max(initial["diameter"]) > fragments.HARDIN_CUTOFF:
        br = [fragments.hardin_breakage(initial, t) for t in tables]
        axes.plot(times, br, label="Br (Hardin)")
    axes.plot(times, [fragments.t10(t, parent_sizes) for t in tables], label="t10")
    axes.set_xlabel("time [s]")
    axes.set_ylabel("breakage index [-]")
    axes.legend()
    written.append(_save(plt, figure, results.directory / "breakage.png"))
    return written


def _frames(directory: Path) -> list[Path]:
    """A run's frames in order: frame_NNNNNN.vtu, or .pvtu when written in pieces."""
    folder = directory / "frames"
    frames = sorted([*folder.glob("frame_*.vtu"), *folder.glob("frame_*.pvtu")])
    if not frames:
        raise InputError(
            f"{folder} holds no frame_*.vtu or .pvtu; give the output directory of a run"
        )
    return frames


def render(directory: str | Path, *, frame: int | None = None, gif: bool = False) -> list[Path]:
    """Write PNG images of the frames (one, or all) and optionally an animated GIF."""
    folder = Path(directory)
    frames = _frames(folder)
    if frame is not None:
        if not 0 <= frame < len(frames):
            raise InputError(
                f"frame {frame} does not exist; the run has frames 0 to {len(frames) - 1}"
            )
        frames = [frames[frame]]
    plt = _pyplot()
    out = folder / "renders"
    out.mkdir(exist_ok=True)
    meshes = [read_vtu_point_data(f) for f in frames]
    points = np.concatenate([positions for positions, _ in meshes])
    is_3d = bool(np.ptp(points[:, 2]) > 0)
    columns = (0, 2) if is_3d else (0, 1)
    lower, upper = points[:, columns].min(axis=0), points[:, columns].max(axis=0)
    margin = 0.05 * float(np.max(upper - lower) or 1.0)
    written = []
    images = []
    for path, (positions, point_data) in zip(frames, meshes, strict=True):
        damage = point_data.get("Damage", np.zeros(len(positions)))
        volume = point_data.get("Nodal_Volume")
        figure, axes = plt.subplots(
            figsize=(
                6,
                6 * (upper[1] - lower[1] + 2 * margin) / (upper[0] - lower[0] + 2 * margin)
                if upper[0] > lower[0]
                else 6,
            )
        )
        size = (
            4.0 if volume is None else np.clip(2e4 * (np.asarray(volume) / np.max(volume)), 1, 20)
        )
        dots = axes.scatter(
            positions[:, columns[0]],
            positions[:, columns[1]],
            c=damage,
            s=size,
            cmap="inferno_r",
            vmin=0,
            vmax=1,
            linewidths=0,
        )
        figure.colorbar(dots, ax=axes, label="damage", shrink=0.8)
        axes.set_xlim(lower[0] - margin, upper[0] + margin)
        axes.set_ylim(lower[1] - margin, upper[1] + margin)
        axes.set_aspect("equal")
        axes.set_title(f"{path.stem}: damage")
        axes.set_xlabel("x [m]")
        axes.set_ylabel("z [m]" if is_3d else "y [m]")
        figure.tight_layout()
        target = out / f"{path.stem}.png"
        figure.savefig(target, dpi=100)
        plt.close(figure)
        written.append(target)
        images.append(target)
    if gif:
        from PIL import Image

        pictures = [Image.open(p).convert("P", palette=Image.ADAPTIVE) for p in images]
        target = out / "run.gif"
        pictures[0].save(target, save_all=True, append_images=pictures[1:], duration=150, loop=0)
        written.append(target)
    return written
