"""Hashes of every output of the example, bench and PeriDEM cases, at 1 and 2 threads.

A refactor that must not change results (issue 16) is checked by running this before and after
and comparing: every case's history.csv, frames (VTU, particle, fragment and contact tables), PVD
series and checkpoint arrays are hashed, with the run record's timings left out. The two thread
counts must agree with each other too (granulate's determinism promise).

    python benchmarks/output_hashes.py --save before.json      # on the old install
    python benchmarks/output_hashes.py --compare before.json   # the new one: exit 1 if any differ

Every run is cut to a few thousand steps; the whole set takes about 2 minutes on 2 cores.

A refactor of the C++ core is checked on builds without floating-point contraction. The default
build (-march=native) lets GCC fuse a*b + c into one FMA wherever its inlining brings the two
together, and that follows the code's layout: moving functions between files (or within one)
changes a few last bits without changing any arithmetic (seen when contact_model.cpp was split:
<= 6.4e-15 relative in two example smokes). Build both versions with the contraction off, point
PYTHONPATH at each, and compare those:

    cmake -S OLD -B old_build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSKBUILD=ON \
        -DCMAKE_CXX_FLAGS=-ffp-contract=off -Dnanobind_DIR=$(python -m nanobind --cmake_dir)
    ninja -C old_build   # then copy the installed granulate package beside its _core*.so
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import runpy
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
PACKAGE_CASES = ROOT / "src" / "granulate" / "bench_cases"
DECKS = ROOT / "tests" / "data" / "peridem"

# name: (case file, steps, extra arguments of `granulate run`)
CASE_RUNS: dict[str, tuple[Path, int, list[str]]] = {
    "pile_2d": (ROOT / "examples/cases/pile_2d.yaml", 3000, []),
    "notched_plate_2d": (ROOT / "examples/cases/notched_plate_2d.yaml", 1500, []),
    "stl_grains_3d": (ROOT / "examples/cases/stl_grains_3d.yaml", 400, []),
    "compression_small": (PACKAGE_CASES / "compression_small/case.yaml", 3000, []),
    "compression_502": (PACKAGE_CASES / "compression_502.yaml", 300, []),
    "twop_circ": (DECKS / "twop_circ/input_0.yaml", 4000, []),
    "twop_circ_compat": (DECKS / "twop_circ/input_0.yaml", 4000, ["--peridem-compat"]),
    "compression_small_set": (DECKS / "compression_small_set/input_0.yaml", 2000, []),
    "attrition_small_set": (DECKS / "attrition_mix_particles_small_set/input_0.yaml", 1500, []),
    "rectangle_compat": (
        DECKS / "single_particle_rectangle_inbuilt_mesh/input_0.yaml",
        1000,
        ["--peridem-compat"],
    ),
}
#: Cases also run in two halves, the second resumed from the first's checkpoint.
RESUMED = ("pile_2d", "compression_small_set")
TIMING_KEYS = ("seconds", "threads", "node_steps")  # run.json keys that hold no result


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


def _file_digest(path: Path) -> str:
    if path.suffix == ".npz":  # the zip entries carry their write time; hash the arrays
        with np.load(path, allow_pickle=False) as arrays:
            parts = [name.encode() + arrays[name].tobytes() for name in sorted(arrays.files)]
        return _digest(b"".join(parts))
    if path.name == "run.json":
        record = json.loads(path.read_text())
        kept = {k: v for k, v in record.items() if not any(t in k for t in TIMING_KEYS)}
        return _digest(json.dumps(kept, sort_keys=True).encode())
    return _digest(path.read_bytes())


def folder_digests(folder: Path) -> dict[str, str]:
    """Every file under folder (logs and figures aside), by its path relative to folder."""
    skipped = {".log", ".png", ".txt"}
    return {
        str(p.relative_to(folder)): _file_digest(p)
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.suffix not in skipped
    }


def _granulate_run(name: str, out: Path, threads: int, work: Path, *arguments: str) -> None:
    """`granulate run` of case `name` into `out` with OMP_NUM_THREADS = threads."""
    case, _steps, extra = CASE_RUNS[name]
    command = [sys.executable, "-m", "granulate", "run", str(case), "--out", str(out), "--quiet"]
    environment = {**os.environ, "OMP_NUM_THREADS": str(threads)}
    subprocess.run(
        [*command, *arguments, *extra],
        check=True,
        env=environment,
        cwd=work,
        stdout=subprocess.DEVNULL,
    )


def run_case(name: str, threads: int, work: Path) -> dict[str, str]:
    out = work / f"{name}_{threads}"
    _granulate_run(name, out, threads, work, "--steps", str(CASE_RUNS[name][1]), "--overwrite")
    return folder_digests(out)


def run_resumed(name: str, threads: int, work: Path) -> dict[str, str]:
    """The case run to half its steps, then resumed from its checkpoint to the end."""
    steps = CASE_RUNS[name][1]
    out = work / f"{name}_resumed_{threads}"
    _granulate_run(name, out, threads, work, "--steps", str(steps // 2), "--overwrite")
    _granulate_run(name, out, threads, work, "--steps", str(steps), "--resume")
    return folder_digests(out)


def run_example(script: Path, threads: int, work: Path) -> dict[str, str]:
    """An example script in its smoke mode, in this process with the thread count set."""
    import granulate as gr

    out = work / f"example_{script.stem}_{threads}"
    shutil.rmtree(out, ignore_errors=True)
    gr.set_num_threads(threads)
    module = runpy.run_path(str(script))
    module["main"](["--out", str(out), "--smoke"])
    return folder_digests(out)


def all_digests(work: Path) -> dict[str, dict[str, str]]:
    examples = sorted([*(ROOT / "examples").glob("*.py"), *(ROOT / "examples").glob("*/*.py")])
    digests: dict[str, dict[str, str]] = {}
    for threads in (1, 2):
        for name in CASE_RUNS:
            digests[f"{name}@{threads}"] = run_case(name, threads, work)
            print(f"{name} at {threads} thread(s): {len(digests[f'{name}@{threads}'])} files")
        for name in RESUMED:
            digests[f"{name}_resumed@{threads}"] = run_resumed(name, threads, work)
            print(f"{name}, resumed, at {threads} thread(s)")
        for script in examples:
            digests[f"example_{script.stem}@{threads}"] = run_example(script, threads, work)
            print(f"{script.stem} at {threads} thread(s)")
    return digests


def differences(a: dict[str, dict[str, str]], b: dict[str, dict[str, str]]) -> list[str]:
    found = []
    for run in sorted(set(a) | set(b)):
        files_a, files_b = a.get(run, {}), b.get(run, {})
        for file in sorted(set(files_a) | set(files_b)):
            if files_a.get(file) != files_b.get(file):
                found.append(f"{run}: {file}")
    return found


def thread_differences(digests: dict[str, dict[str, str]]) -> list[str]:
    ones = {k[:-2]: v for k, v in digests.items() if k.endswith("@1")}
    twos = {k[:-2]: v for k, v in digests.items() if k.endswith("@2")}
    return differences(ones, twos)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--work", type=Path, default=Path("output_hashes_runs"))
    parser.add_argument("--save", type=Path, help="write the hashes to this JSON file")
    parser.add_argument("--compare", type=Path, help="compare with hashes saved earlier")
    args = parser.parse_args(argv)
    args.work.mkdir(parents=True, exist_ok=True)
    digests = all_digests(args.work.resolve())
    failed = False
    for line in thread_differences(digests):
        print(f"1 and 2 threads differ: {line}")
        failed = True
    if args.save:
        args.save.write_text(json.dumps(digests, indent=1, sort_keys=True))
    if args.compare:
        changed = differences(json.loads(args.compare.read_text()), digests)
        for line in changed:
            print(f"changed: {line}")
        failed = failed or bool(changed)
    count = sum(len(files) for files in digests.values())
    print(f"{len(digests)} runs, {count} files: {'DIFFERENCES' if failed else 'all identical'}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
