"""Batch design verification (``gearcli verify``): manifests, parallel runs, reports.

:mod:`manifest` reads and validates a manifest and every file it names, :mod:`runner`
evaluates the checks (serially, in processes or on Dask), :mod:`outputs` writes the
reports, :mod:`verify` ties them together.  Sits above :mod:`gearcli.pipeline`.
"""
