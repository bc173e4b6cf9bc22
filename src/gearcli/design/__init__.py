"""Design checks: component ratings against the loads along a duty cycle.

:mod:`bearings` (ISO 281 life, ISO 76 static safety, two-bearing split), :mod:`gears`
(Lewis bending, Hertz contact stress), :mod:`motors` (RMS torque, power), and
:mod:`checks` (the checks of one mechanism, evaluated on one trajectory at a time).
May import :mod:`gearcli.model`, ``analysis``, ``dynamics`` and ``report``.
"""
