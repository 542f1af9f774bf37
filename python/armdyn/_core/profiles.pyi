"""
Built-in drive and load profiles (evaluated in C++).
"""
from __future__ import annotations
import armdyn._core
import numpy.typing
import typing
__all__: list[str] = ['constant', 'cubic', 'quintic', 'sine', 'spline']
def constant(value: typing.SupportsFloat | typing.SupportsIndex) -> armdyn._core.Profile:
    """
    The constant profile y(t) = value (zero derivatives).
    """
def cubic(y0: typing.SupportsFloat | typing.SupportsIndex, y1: typing.SupportsFloat | typing.SupportsIndex, t0: typing.SupportsFloat | typing.SupportsIndex, t1: typing.SupportsFloat | typing.SupportsIndex) -> armdyn._core.Profile:
    """
    Cubic rest-to-rest from y0 at t0 to y1 at t1 (3s^2 - 2s^3); constant outside.
    """
def quintic(y0: typing.SupportsFloat | typing.SupportsIndex, y1: typing.SupportsFloat | typing.SupportsIndex, t0: typing.SupportsFloat | typing.SupportsIndex, t1: typing.SupportsFloat | typing.SupportsIndex) -> armdyn._core.Profile:
    """
    Quintic rest-to-rest (zero velocity and acceleration at both ends).
    """
def sine(amplitude: typing.SupportsFloat | typing.SupportsIndex, frequency: typing.SupportsFloat | typing.SupportsIndex, phase: typing.SupportsFloat | typing.SupportsIndex = 0.0, offset: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> armdyn._core.Profile:
    """
    offset + amplitude * sin(2 pi frequency t + phase); frequency in Hz.
    """
def spline(t: numpy.typing.ArrayLike, y: numpy.typing.ArrayLike) -> armdyn._core.Profile:
    """
    Natural cubic spline through the samples (t[k], y[k]), t (n,) increasing [s], y (n,); linear extrapolation outside [t[0], t[-1]].
    """
