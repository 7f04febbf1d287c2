"""Command line: ``granulate`` (also ``python -m granulate``).

    granulate check CASE.yaml                  validate, build and summarise without running
    granulate run CASE.yaml [--out DIR] [--resume] [--overwrite]
    granulate run input_0.yaml [--peridem-compat]   a PeriDEM deck, translated
    granulate convert input_0.yaml -o case.yaml     write a PeriDEM deck as a granulate case
    granulate run SCRIPT.py [ARGS...]          run a Python set-up script
    granulate plot DIR                         PNG plots from DIR/history.csv, DIR/frames
    granulate render DIR [--frame N] [--gif]   PNG images (and a GIF) of the particles
    granulate schema [--json]                  the case-file reference (or its JSON Schema)
    granulate bench [--quick] [--case NAME ...] [--threads N] [--json] [--contended]
    mpirun -n K granulate bench --ranks [--case NAME] [--steps S] [--grains N] [--collect-every N]
                                [--load-balance every=N,threshold=T,weight=work|time]
    granulate info                             version, build options, threads

Exit codes: 0 success, 2 invalid input, 1 failed run, 130 interrupted. User errors print one
line (``--debug`` shows the traceback).

``mpirun -n K granulate run CASE.yaml`` runs the case on K MPI ranks (granulate.parallel; the
``mpi`` extra installs mpi4py): the same outputs as the serial run, written by rank 0, which
also prints; a rank's own failure is printed by that rank. ``bench --ranks`` measures a
distributed run (granulate.bench_ranks). The other commands that write files refuse to start as
several ranks (granulate.parallel.launch).
"""

from __future__ import annotations

import argparse
import json
import runpy
import sys
import time
import warnings
from pathlib import Path

from granulate import _core, resources, threads
from granulate._version import __version__
from granulate.errors import InputError, InstabilityError
from granulate.io.files import existing_file
from granulate.io.run_folder import check_writable
from granulate.load_balance import LoadBalance
from granulate.parallel.agreement import RankFailed
from granulate.parallel.launch import launched_ranks, serial_only_message
from granulate.progress import ProgressReporter, duration


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings as one line for the user (not the code location)."""
    print(f"granulate: warning: {message}", file=sys.stderr)


def _info() -> int:
    print(f"granulate {__version__}")
    build = _core.build_info()
    print(
        f"core: {Path(_core.__file__).name} (C++20; {build['compiler']}, {build['build_type']}, "
        f"{build['cpu_tuning']}; OpenMP {build['openmp']}; {build['precision']} precision, "
        f"{build['index_bits']}-bit indices; warnings as errors: "
        f"{'yes' if build['warnings_as_errors'] else 'no'})"
    )
    policy = (
        "adaptive: runs use fewer when that is faster, as on a busy machine"
        if threads.is_adaptive()
        else "fixed by OMP_NUM_THREADS, --threads or set_num_threads"
    )
    print(
        f"threads: {threads.get_num_threads()} ({policy}; CPUs usable: {threads.available_cpus()})"
    )
    print(f"python: {sys.version.split()[0]}")
    return 0


def _schema(as_json: bool) -> int:
    from granulate import case

    if as_json:
        print(json.dumps(case.schema(), indent=2))
    else:
        print(case.reference())
    return 0


def _notes(case) -> None:
    """Say once what a translated PeriDEM deck runs differently."""
    if case.notes:
        print(f"{case.source.name}: PeriDEM deck, translated; differences from PeriDEM:")
        for note in case.notes:
            print(f"  - {note}")


def _convert(deck: Path, target: Path, compat: bool, overwrite: bool) -> int:
    from granulate import peridem
    from granulate.case import parse_case
    from granulate.io.atomic import atomic_write

    if target.exists() and not overwrite:
        raise InputError(f"{target} exists; choose another name or pass --overwrite")
    translation = peridem.translate(deck, compat=compat, output=target.resolve().parent)
    text = peridem.to_yaml(translation, compat)
    parse_case(text, target.resolve())  # what is written must load as a case
    atomic_write(target, text.encode())
    print(f"wrote {target} ({len(translation.case.get('particles', []))} placed particles)")
    for note in translation.notes:
        print(f"  - {note}")
    return 0


def _announce_setup(case) -> None:
    """Say before a long set-up (a packing of many grains) that it will take a while."""
    grains = sum(packing.count for packing in case.spec.packings)
    seconds = resources.setup_seconds(case.spec.dimension, grains)
    if seconds >= 20:
        print(f"packing {grains:,} grains: set-up takes about {duration(seconds)}", flush=True)


def _check(path: Path, compat: bool = False) -> int:
    from granulate.case import load_case

    case = load_case(path, peridem_compat=compat)
    _notes(case)
    _announce_setup(case)
    sim = case.build(outputs=False)
    case.stop_criteria()  # names of walls in stop criteria
    spec = case.spec.output
    check_writable(Path(spec.directory) if spec is not None else Path("out") / path.stem)
    steps = case.steps(sim)
    model = sim.model
    memory = model.shared_bond_bytes() + sim.bond_count + resources.BYTES_PER_NODE * sim.node_count
    sim.run(1)  # builds the core and the first forces and contact lists: not timed
    probe = max(1, min(50, steps))
    most, adaptive = threads.get_num_threads(), threads.is_adaptive()
    # A run picks the fastest thread count on a busy machine (granulate.threads): so does the
    # estimate, from one probe at each count a run would try (each at that count only).
    counts = threads.candidate_counts(most) if adaptive else [most]
    rates = {}
    for count in counts:
        threads.set_num_threads(count, adaptive=False)
        start = time.perf_counter()
        sim.run(probe)
        rates[count] = probe / max(time.perf_counter() - start, 1e-9)
    threads.set_num_threads(most, adaptive=adaptive)
    fastest = max(rates, key=lambda count: rates[count])
    rate = rates[fastest]
    print(f"{path}: valid")
    print(
        f"  dimension {sim.dimension}, {len(sim.bodies)} particles, {sim.node_count} nodes, "
        f"{sim.bond_count} bonds"
    )
    for packing in sim.packings:
        print(f"  packing: {packing.summary()}")
    print(f"  walls: {', '.join(name for name, _ in sim.walls) or 'none'}")
    print(f"  dt {sim.dt:.4g} s (stable estimate {sim.stable_dt:.4g} s); {steps} steps to the end")
    print(
        f"  estimated memory {memory / 1e6:.1f} MB; estimated time {duration(steps / rate)} "
        f"with {fastest} of {most} threads"
    )
    return 0


def _run_case(
    path: Path,
    out: Path | None,
    resume: bool,
    overwrite: bool,
    quiet: bool,
    limit: int | None,
    compat: bool = False,
) -> int:
    from granulate.case import load_case

    comm = _world()
    speaks = comm is None or comm.Get_rank() == 0  # rank 0 prints for every rank
    case = load_case(path, peridem_compat=compat)
    if speaks:
        _notes(case)
    if out is None and case.spec.output is None:
        out = Path("out") / path.stem
    if speaks:
        _announce_setup(case)
    sim = case.build(output=out, resume=resume, overwrite=overwrite, comm=comm)
    directory = sim.output_directory
    assert directory is not None
    if sim.checkpoint_path is None:  # a checkpoint on interrupt, at least
        sim.checkpoint_every(path=directory / "checkpoint.npz")
    if resume:
        sim.load_checkpoint(sim.checkpoint_path)
        if speaks:
            print(f"resuming from step {sim.step} (t = {sim.time:.6g} s)")
    steps = case.steps(sim)
    cut_short = False
    if limit is not None:
        if limit <= 0:
            raise InputError(f"--steps must be positive, got {limit}")
        cut_short = limit < steps
        steps = min(steps, limit)
    stop = case.stop_criteria()
    check_every = case.spec.stop.check_every if case.spec.stop is not None else 100
    if not quiet and speaks:
        dealt = {"grains": "whole grains per rank", "nodes": "the bodies cut at node level"}
        ranks = (
            "" if comm is None else f" on {comm.Get_size()} MPI ranks, {dealt[sim.distribution]}"
        )
        print(
            f"{sim.node_count} nodes, {sim.bond_count} bonds, dt {sim.dt:.4g} s, {steps} steps"
            f"{ranks}; output in {directory}"
        )
    reporter = ProgressReporter(steps, quiet or not speaks)
    try:
        # A run cut short by --steps is continued with --resume as if never stopped, so it
        # ends like an interrupted one: no extra frame at its last step.
        # On ranks, rank 0 takes the whole state only when an output reads it: the command
        # reads the run's measures (every rank together), not rank 0's simulation.
        reason = sim.run(
            steps,
            stop=stop,
            check_every=check_every,
            progress=reporter,
            write_final=not cut_short,
            gather=False,
        )
    finally:
        reporter.close()
    sim.save_checkpoint(sim.checkpoint_path)
    broken = sim.measures().broken_bonds()
    if not speaks:
        return 0
    summary = sim.summary()
    rate = summary["nodes"] * summary["steps_run"] / max(summary["wall_seconds"], 1e-9)
    ended = f"stopped: {reason}" if reason else "finished"
    print(
        f"{ended} at step {sim.step} (t = {sim.time:.6g} s) in {summary['wall_seconds']:.1f} s, "
        f"{rate / 1e6:.2f} M node-steps/s, {broken} broken bonds"
    )
    return 0


def _world(command: str = "run", required: bool = False) -> object | None:
    """MPI's world communicator when this process was started as one of several ranks (mpirun,
    mpiexec, srun) or the command is `required` to have one, else None. InputError when mpi4py
    is missing or belongs to another MPI than the launcher's (each process would see itself
    alone and run the whole case)."""
    size, _rank = launched_ranks()
    if size == 1 and not required:
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        problem = (
            f"was started as {size} MPI processes, but mpi4py is not installed"
            if size > 1
            else "needs mpi4py, which is not installed"
        )
        raise InputError(
            f"granulate {command} {problem}: pip install 'granulate[mpi]' (or mpi4py built "
            "against your cluster's MPI)"
        ) from None
    if size > 1 and MPI.COMM_WORLD.Get_size() != size:  # else the one world mpi4py sees
        raise InputError(
            f"the launcher started {size} processes, but mpi4py's MPI sees "
            f"{MPI.COMM_WORLD.Get_size()}: mpi4py belongs to another MPI than this mpirun. Use "
            "the mpirun of the MPI mpi4py was built with (python -c 'import mpi4py; "
            "print(mpi4py.get_config())')"
        )
    return MPI.COMM_WORLD


def _run_script(script: Path, args: list[str]) -> int:
    existing_file(script, "script")
    sys.argv = [str(script), *args]
    runpy.run_path(str(script), run_name="__main__")
    return 0


def main(argv: list[str] | None = None) -> int:
    """The command line; warnings are printed as one line each while it runs."""
    previous = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        return _main(argv)
    finally:
        warnings.showwarning = previous


def _parser() -> argparse.ArgumentParser:
    """The command line: global options and one sub-parser per command."""
    parser = argparse.ArgumentParser(prog="granulate", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"granulate {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    parser.add_argument("--threads", type=int, help="number of OpenMP threads")
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("info", help="print version, build options and thread count")
    schema = commands.add_parser("schema", help="print the case-file reference")
    schema.add_argument("--json", action="store_true", help="the JSON Schema, for editors")
    compat_help = "PeriDEM deck: PeriDEM's formulas where granulate has them (comparisons)"
    check = commands.add_parser("check", help="validate a case and print a summary")
    check.add_argument("case", type=Path)
    check.add_argument("--peridem-compat", action="store_true", help=compat_help)
    convert = commands.add_parser("convert", help="write a PeriDEM deck as a granulate case")
    convert.add_argument("deck", type=Path)
    convert.add_argument("-o", "--output", type=Path, required=True, help="the case file to write")
    convert.add_argument("--peridem-compat", action="store_true", help=compat_help)
    convert.add_argument("--overwrite", action="store_true", help="replace an existing file")
    run = commands.add_parser("run", help="run a case (.yaml) or a Python script (.py)")
    run.add_argument("case", type=Path)
    run.add_argument("--out", type=Path, help="output directory (default: the case's)")
    run.add_argument("--resume", action="store_true", help="continue from the last checkpoint")
    run.add_argument(
        "--overwrite", action="store_true", help="replace an earlier run in the output directory"
    )
    run.add_argument("--quiet", action="store_true", help="no progress lines")
    run.add_argument(
        "--steps", type=int, help="run at most this many steps (a trial run; --resume continues it)"
    )
    run.add_argument("--peridem-compat", action="store_true", help=compat_help)
    run.add_argument("args", nargs="*", help="arguments passed to a script (after --)")
    bench = commands.add_parser("bench", help="run the benchmark cases (shipped with granulate)")
    bench.add_argument("--quick", action="store_true", help="small sizes, a smoke check")
    bench.add_argument("--case", action="append", help="a case (repeatable; default: all)")
    bench.add_argument("--json", action="store_true", help="one JSON object per case")
    bench.add_argument(
        "--contended",
        action="store_true",
        help="next to one busy process: 1 thread, all fixed, all adaptive",
    )
    bench.add_argument("--out", type=Path, default=Path("out") / "bench", help="scratch output")
    bench.add_argument(
        "--ranks",
        action="store_true",
        help="a distributed run on the MPI ranks this is launched on (mpirun -n K): per rank "
        "node-steps/s and communication shares; cases pile3d (default), pile, drum, fine2d, "
        "shatter, block (one body cut at node level)",
    )
    bench.add_argument("--steps", type=int, help="with --ranks: timed steps (default 300)")
    bench.add_argument("--grains", type=int, help="with --ranks: grains (default: the case's)")
    bench.add_argument(
        "--collect-every",
        type=int,
        default=0,
        help="with --ranks: gather the whole state on rank 0 every N steps (0: never)",
    )
    bench.add_argument(
        "--load-balance",
        metavar="KEY=VALUE,...",
        help="with --ranks: when the ranks compare their work and cut anew, as gr.LoadBalance "
        "takes it (default every=100,threshold=1.1,weight=work; weight=time follows the "
        "measured step seconds)",
    )
    plot = commands.add_parser("plot", help="PNG plots of a run's history.csv and fragment tables")
    plot.add_argument("directory", type=Path)
    render = commands.add_parser("render", help="PNG images of the particles coloured by damage")
    render.add_argument("directory", type=Path)
    render.add_argument("--frame", type=int, help="only this frame (default: all)")
    render.add_argument("--gif", action="store_true", help="also an animated GIF of the run")
    return parser


def _dispatch(options: argparse.Namespace) -> int:
    """Run the command `options` name; its exit code."""
    if options.command == "info":
        return _info()
    if options.command == "schema":
        return _schema(options.json)
    if options.command == "check":
        return _check(options.case, options.peridem_compat)
    if options.command == "convert":
        return _convert(options.deck, options.output, options.peridem_compat, options.overwrite)
    if options.command == "run":
        if options.case.suffix == ".py":
            return _run_script(options.case, options.args)
        if options.args:
            raise InputError(f"unexpected arguments {options.args} after the case file")
        return _run_case(
            options.case,
            options.out,
            options.resume,
            options.overwrite,
            options.quiet,
            options.steps,
            options.peridem_compat,
        )
    if options.command == "bench":
        from granulate import bench as benchmarks

        if options.ranks:
            return _bench_ranks(options)
        ranks_only = (options.steps, options.grains, options.load_balance)
        if any(option is not None for option in ranks_only) or options.collect_every:
            raise InputError(
                "bench: --steps, --grains, --collect-every and --load-balance go with --ranks"
            )
        if options.contended:
            return benchmarks.contended(options.case, options.quick, options.json, options.out)
        return benchmarks.main(options.case, options.quick, None, options.json, options.out)
    from granulate import plots

    if options.command == "plot":
        for written in plots.plot_history(options.directory):
            print(written)
        return 0
    for written in plots.render(options.directory, frame=options.frame, gif=options.gif):
        print(written)
    return 0


def _bench_ranks(options: argparse.Namespace) -> int:
    """`granulate bench --ranks`: the distributed benchmark on the ranks this process was
    launched among (one, without a launcher), one thread each unless --threads."""
    from granulate import bench_ranks

    cases = options.case or []
    if options.contended or len(cases) > 1:
        raise InputError("bench --ranks runs one case, and not --contended")
    comm = _world("bench --ranks", required=True)
    if options.threads is None:
        threads.set_num_threads(1, adaptive=False)
    case = cases[0] if cases else None
    balance = options.load_balance
    return bench_ranks.main(
        comm,
        case,
        options.grains,
        options.steps,
        options.collect_every,
        options.quick,
        options.json,
        None if balance is None else LoadBalance.from_text(balance),
    )


def _writes_output(options: argparse.Namespace) -> bool:
    """Whether a command writes files that copies of it on several MPI ranks would write at
    once: not `run` (a case runs over the ranks; a Python script is the user's own, and may
    use them itself) nor `bench --ranks` (which measures the ranks, writing nothing)."""
    if options.command == "bench" and options.ranks:
        return False
    return options.command not in ("info", "schema", "check", "run")


def _main(argv: list[str] | None) -> int:
    parser = _parser()
    options, extra = parser.parse_known_args(argv)
    if extra and not (options.command == "run" and options.case.suffix == ".py"):
        parser.error(f"unrecognized arguments: {' '.join(extra)}")
    if extra:
        options.args = [*options.args, *extra]
    size, rank = launched_ranks()
    if size > 1 and _writes_output(options):
        if rank == 0:  # once, not once per rank
            message = serial_only_message(options.command, size)
            print(f"granulate: error: {message}", file=sys.stderr)
        return 2
    if size > 1 and rank != 0 and options.command in ("info", "schema", "check"):
        return 0  # rank 0 prints it once
    return _handled(options, rank == 0)


def _handled(options: argparse.Namespace, first_rank: bool) -> int:
    """The command `options` name, its errors turned into one line and an exit code. Of a
    distributed run's errors, those every rank raises alike are printed by rank 0 alone
    (`first_rank`), a rank's own failure by that rank."""

    def shared(text: str) -> None:
        if first_rank:
            print(text, file=sys.stderr)

    try:
        if options.threads is not None:
            threads.set_num_threads(options.threads)
        return _dispatch(options)
    except InputError as error:
        if options.debug:
            raise
        shared(f"granulate: error: {error}")
        return 2
    except InstabilityError as error:
        if options.debug:
            raise
        print(f"granulate: run failed: {error}", file=sys.stderr)
        return 1
    except RankFailed as error:  # another rank's failure, which that rank prints
        if options.debug:
            raise
        shared(f"granulate: run failed: {error}")
        return 1
    except KeyboardInterrupt as error:
        shared(f"granulate: {error or 'interrupted'}")
        return 130
    except OSError as error:  # a full disk, a file system gone read-only, a lost mount
        if options.debug:
            raise
        where = f" {error.filename}" if error.filename else ""
        print(
            f"granulate: run failed: could not write{where}: {error.strerror or error}; the "
            "outputs written before are intact (free space or fix the folder, then --resume)",
            file=sys.stderr,
        )
        return 1
