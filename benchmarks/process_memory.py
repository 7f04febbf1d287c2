"""This process's memory as Linux reports it (/proc/self/status), for the benchmarks that print
what a rank holds."""

from __future__ import annotations


def status_mb(*names: str) -> tuple[float, ...]:
    """The fields `names` of /proc/self/status (VmRSS: resident now, VmHWM: its peak) [MB]."""
    fields = {}
    with open("/proc/self/status") as status:
        for line in status:
            name, _, value = line.partition(":")
            fields[name] = value
    return tuple(float(fields[name].split()[0]) / 1024 for name in names)


def resident_mb() -> float:
    """VmRSS of this process [MB]."""
    return status_mb("VmRSS")[0]
