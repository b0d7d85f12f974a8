"""Argument checks shared by the public API (vrlib's and data_gen's).

Every check raises a ``ValueError`` (or ``TypeError`` for a wrong kind of object) whose message
names the parameter, what was given, and what is allowed.
"""

from __future__ import annotations

import math
import numbers

import numpy as np


def finite_number(name, value, *, low=None, high=None, low_open=False, high_open=False):
    """Return ``value`` as a float after checking it is a finite real within bounds.

    ``low_open`` / ``high_open`` make the corresponding bound exclusive.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if low is not None and (value < low or (low_open and value == low)):
        rel = ">" if low_open else ">="
        raise ValueError(f"{name} must be {rel} {low}, got {value!r}")
    if high is not None and (value > high or (high_open and value == high)):
        rel = "<" if high_open else "<="
        raise ValueError(f"{name} must be {rel} {high}, got {value!r}")
    return value


def positive_number(name, value):
    """Return ``value`` as a float after checking it is finite and strictly positive."""
    return finite_number(name, value, low=0.0, low_open=True)


def positive_int(name, value, *, minimum=1):
    """Return ``value`` as an int after checking it is an integer >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value}")
    return value


def vector3(name, value, *, unit=False):
    """Return ``value`` as a finite float64 3-vector; with ``unit`` normalise it (non-zero)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be three real numbers, got {value!r}") from None
    if arr.shape != (3,):
        raise ValueError(f"{name} must have three components, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    if unit:
        norm = float(np.linalg.norm(arr))
        if norm == 0.0:
            raise ValueError(f"{name} must be a non-zero vector, got {arr.tolist()}")
        arr = arr / norm
    return arr


def finite_array(name, value, *, ndim=None, dtype=np.float64):
    """Return ``value`` as a finite array of ``dtype`` (optionally of fixed ``ndim``)."""
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"{name} must hold real numbers, got dtype {arr.dtype}")
    arr = arr.astype(dtype, copy=False)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-dimensional, got shape {arr.shape}")
    # A NaN or infinity anywhere makes the sum non-finite; a finite sum proves all are finite
    # (one pass, no temporary), and only an overflowing sum needs the element-wise test.
    with np.errstate(over="ignore", invalid="ignore"):
        total = arr.sum()
    if arr.size and not np.isfinite(total) and not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must hold only finite values (found NaN or infinity)")
    return arr


def choice(name, value, allowed):
    """Check that ``value`` is one of ``allowed`` (strings), naming them all if not."""
    if value not in allowed:
        listed = ", ".join(repr(a) for a in allowed)
        raise ValueError(f"unknown {name} {value!r}; known: {listed}")
    return value
