"""Runs the C++ unit tests (evaluators against analytic values and finite differences, bond
families, input errors), built and installed beside the extension module."""

from __future__ import annotations

import subprocess
from pathlib import Path

import granulate


def test_cpp_unit_tests_pass() -> None:
    binary = Path(granulate._core.__file__).with_name("granulate_core_tests")
    assert binary.is_file(), f"C++ test binary missing at {binary}"
    result = subprocess.run([str(binary)], capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    passed, failed = (int(word) for word in result.stdout.split()[0:3:2])
    assert failed == 0 and passed >= 17, result.stdout
