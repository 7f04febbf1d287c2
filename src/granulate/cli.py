"""Command line: ``granulate info`` (version, build, threads) and ``granulate run SCRIPT.py``.

User errors (InputError, InstabilityError) print one line and exit with 2 (bad input) or 1
(failed run); ``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path

from granulate import __version__, _core
from granulate.errors import InputError, InstabilityError


def _info() -> int:
    print(f"granulate {__version__}")
    print(f"core: {Path(_core.__file__).name} (C++20, OpenMP)")
    print(f"threads: {_core.get_max_threads()} (set OMP_NUM_THREADS or --threads)")
    print(f"python: {sys.version.split()[0]}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="granulate", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"granulate {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    parser.add_argument("--threads", type=int, help="number of OpenMP threads")
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("info", help="print version, build options and thread count")
    run = commands.add_parser("run", help="run a Python set-up script")
    run.add_argument("script", type=Path)
    run.add_argument("args", nargs=argparse.REMAINDER, help="arguments passed to the script")
    options = parser.parse_args(argv)
    try:
        if options.threads is not None:
            _core.set_num_threads(options.threads)
        if options.command == "info":
            return _info()
        if not options.script.is_file():
            raise InputError(f"script {options.script} does not exist")
        sys.argv = [str(options.script), *options.args]
        runpy.run_path(str(options.script), run_name="__main__")
        return 0
    except InputError as error:
        if options.debug:
            raise
        print(f"granulate: error: {error}", file=sys.stderr)
        return 2
    except InstabilityError as error:
        if options.debug:
            raise
        print(f"granulate: run failed: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("granulate: interrupted", file=sys.stderr)
        return 130
