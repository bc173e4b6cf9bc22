"""Design checks: component ratings against the loads along a duty cycle.

:mod:`bearings` (rating life, ISO 76 static safety, two-bearing split), :mod:`iso281` (the
ISO 281 load factors, bearing types, a_ISO), :mod:`gears` (Lewis bending, Hertz contact
stress; the RMS is :mod:`gearcli.report.rms`), and
:mod:`checks` (the checks of one mechanism, evaluated on one trajectory at a time).
May import :mod:`gearcli.model`, ``analysis``, ``dynamics`` and ``report``.
"""
import numpy as np


def magnitudes(x, *others) -> np.ndarray:
    """abs(x) as a new float array of the shape x broadcasts to with ``others`` (0-d for
    numbers), which the caller may change in place with any of them: the checks' formulas
    run in place on it, as each (N,) temporary of a sweep's dozens of checks a variant
    costs a pass over memory."""
    out = np.empty(np.broadcast_shapes(np.shape(x), *(np.shape(v) for v in others)))
    return np.abs(np.asarray(x, float), out=out)
