"""An output directory's life: refuse one that holds another run or cannot hold one, replace an
old run only when the new one starts writing, clean the temporaries of interrupted writes, and
lock the directory while a run writes into it."""

from __future__ import annotations

import json
import os
import shutil
import socket
from pathlib import Path

from granulate.errors import InputError
from granulate.io.checkpoint import PIECES_SUFFIX
from granulate.resources import size_text

LOCK = ".granulate.lock"
#: What a run writes (replaced together with --overwrite).
RUN_FILES = ("simulation.pvd", "contacts.pvd", "history.csv", "run.json", "checkpoint.npz")
#: The pieces of a distributed run's checkpoint.npz (granulate.checkpoints.pieces_folder).
CHECKPOINT_PIECES = "checkpoint.npz" + PIECES_SUFFIX
FRAME_PATTERNS = ("frame_*.vtu", "frame_*.pvtu", "particles_*.csv")


def _holds_run(path: Path) -> bool:
    frames = path / "frames"
    return (path / "simulation.pvd").exists() or (
        frames.is_dir() and any(any(frames.glob(p)) for p in FRAME_PATTERNS)
    )


#: The longest name of one folder or file most file systems take.
LONGEST_NAME = 255


def check_writable(path: Path) -> None:
    """InputError if `path` cannot become a directory this process writes into."""
    text = str(path)
    if "\0" in text:
        raise InputError(f"output directory {text!r} holds a NUL character; choose another name")
    long = [part for part in path.parts if len(part.encode()) > LONGEST_NAME]
    if long:
        raise InputError(
            f"output directory {path}: the name {long[0][:40]}... is longer than "
            f"{LONGEST_NAME} bytes; choose a shorter one"
        )
    for parent in [path, *path.parents]:
        if parent.exists():
            if not parent.is_dir():
                where = "is a file" if parent == path else f"is under the file {parent}"
                raise InputError(f"output directory {path} {where}; choose another directory")
            if not os.access(parent, os.W_OK | os.X_OK):
                raise InputError(
                    f"output directory {path}: {parent} is not writable by you; choose another "
                    "directory"
                )
            return


def _existing_parent(path: Path) -> Path:
    for parent in [path, *path.parents]:
        if parent.exists():
            return parent
    return Path.cwd()


def _alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class RunFolder:
    """The directory of one run's outputs (see the module docstring)."""

    def __init__(self, path: Path, overwrite: bool, resume: bool) -> None:
        if overwrite and resume:
            raise InputError("overwrite and resume exclude each other")
        check_writable(path)
        holds_run = _holds_run(path)
        if holds_run and not (overwrite or resume):
            raise InputError(
                f"{path} already holds a run (simulation.pvd or frames); choose another "
                "directory, replace it (overwrite=True; granulate run --overwrite) or continue it "
                "(granulate run --resume)"
            )
        self.path = path
        self._replace = overwrite and holds_run
        self._locked = False
        if resume:
            self.clean_temporaries()

    def require_space(self, frames: int, bytes_per_frame: float) -> None:
        """InputError when `frames` frames of about `bytes_per_frame` would not fit on the
        disk (an output interval far too small for the run)."""
        usage = shutil.disk_usage(_existing_parent(self.path))
        if usage.total == 0:
            return  # not a disk (/proc, /sys): making the folder will say what is wrong
        free, needed = usage.free, frames * bytes_per_frame
        if needed > free:
            raise InputError(
                f"the run would write {frames:,} frames, about {size_text(needed)}, to "
                f"{self.path}, and the disk has {size_text(free)} free; write frames less often "
                "(output every)"
            )

    def start_writing(self) -> None:
        """Before a run writes: take the lock (InputError if another live process holds it),
        replace the old run if asked (only now, so an input error found earlier leaves it
        intact), and make frames/."""
        try:
            (self.path / "frames").mkdir(parents=True, exist_ok=True)
        except OSError as error:  # a read-only or device tree, a full disk
            raise InputError(
                f"output directory {self.path} cannot be made: {error.strerror or error}"
            ) from None
        self._lock()
        if self._replace:
            self._replace = False
            for name in RUN_FILES:
                (self.path / name).unlink(missing_ok=True)
            for pattern in FRAME_PATTERNS:
                for old in (self.path / "frames").glob(pattern):
                    old.unlink()
            for pieces in (self.path / "frames").glob("frame_*"):  # frames written in pieces
                if pieces.is_dir():
                    shutil.rmtree(pieces)
            if (self.path / CHECKPOINT_PIECES).is_dir():
                shutil.rmtree(self.path / CHECKPOINT_PIECES)
            self.clean_temporaries()

    def stop_writing(self) -> None:
        """After a run (also a failed one): release the lock."""
        if self._locked:
            (self.path / LOCK).unlink(missing_ok=True)
            self._locked = False

    def clean_temporaries(self) -> None:
        """Remove the temporary files of atomic writes that were interrupted (.<name>.*.tmp)."""
        pieces = [p for p in self.path.glob("frames/frame_*") if p.is_dir()]
        for folder in (self.path, self.path / "frames", *pieces):
            if folder.is_dir():
                for temporary in folder.glob(".*.tmp"):
                    temporary.unlink(missing_ok=True)

    def _lock(self) -> None:
        if self._locked:
            return
        lock = self.path / LOCK
        owner = {"pid": os.getpid(), "host": socket.gethostname()}
        for _ in range(2):
            try:
                descriptor = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                if not self._stale(lock):
                    holder = lock.read_text(errors="replace").strip()
                    raise InputError(
                        f"another run is writing into {self.path} ({holder}); choose another "
                        f"directory, or remove {lock} if that run is over"
                    ) from None
                lock.unlink(missing_ok=True)
                continue
            with os.fdopen(descriptor, "w") as handle:
                handle.write(json.dumps(owner))
            self._locked = True
            return

    @staticmethod
    def _stale(lock: Path) -> bool:
        """A lock left by a process of this host that is gone (or unreadable)."""
        try:
            owner = json.loads(lock.read_text())
        except (OSError, ValueError):
            return True
        if owner.get("host") != socket.gethostname():
            return False  # another machine's process: it may be alive
        return not _alive(int(owner.get("pid", -1)))
