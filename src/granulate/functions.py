"""Time functions f(t) for prescribed motion and loads (evaluated in the C++ core).

=====================  =====================================  =========================
class                  f(t)                                   parameters
=====================  =====================================  =========================
Constant(a)            a                                      a
Linear(rate)           rate * t                               rate [unit/s]
Quadratic(a, b)        a t + b t^2                            a [unit/s], b [unit/s^2]
Sine(amplitude, f)     amplitude * sin(2 pi f t)              f [Hz]
SmoothRamp(value, T)   value * S(t/T), S = 3s^2 - 2s^3, 1     T [s]
VelocityRamp(rate, T)  f' rises smoothly to rate over T       T [s]
=====================  =====================================  =========================
"""

from __future__ import annotations

from dataclasses import dataclass

from granulate import _core
from granulate.input_errors import checked_arguments


@dataclass(frozen=True)
class TimeFunction:
    """Base: a kind known to the core and two parameters a, b."""

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        """(kind, a, b) as the C++ core takes them."""
        raise TypeError(f"{type(self).__name__} is not a concrete time function; use a subclass")

    def at(self, t: float) -> float:
        """f(t)."""
        kind, a, b = self.core()
        return _core.time_function_value(kind, a, b, t)

    def rate_at(self, t: float) -> float:
        """f'(t)."""
        kind, a, b = self.core()
        return _core.time_function_rate(kind, a, b, t)


@checked_arguments
@dataclass(frozen=True)
class Constant(TimeFunction):
    value: float = 1.0

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        return _core.TimeFunctionKind.constant, float(self.value), 0.0


@checked_arguments
@dataclass(frozen=True)
class Linear(TimeFunction):
    rate: float

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        return _core.TimeFunctionKind.linear, float(self.rate), 0.0


@checked_arguments
@dataclass(frozen=True)
class Quadratic(TimeFunction):
    a: float
    b: float

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        return _core.TimeFunctionKind.quadratic, float(self.a), float(self.b)


@checked_arguments
@dataclass(frozen=True)
class Sine(TimeFunction):
    amplitude: float
    frequency: float

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        return _core.TimeFunctionKind.sine, float(self.amplitude), float(self.frequency)


@checked_arguments
@dataclass(frozen=True)
class SmoothRamp(TimeFunction):
    target: float
    duration: float

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        return _core.TimeFunctionKind.smooth_ramp, float(self.target), float(self.duration)


@checked_arguments
@dataclass(frozen=True)
class VelocityRamp(TimeFunction):
    rate: float
    duration: float

    def core(self) -> tuple[_core.TimeFunctionKind, float, float]:
        return _core.TimeFunctionKind.velocity_ramp, float(self.rate), float(self.duration)
