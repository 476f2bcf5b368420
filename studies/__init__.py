"""Lab scripts: the studies behind the figures in docs/, run from the repository root as
``python -m studies.NAME ...``. Not part of the simkit package (not in the wheel); simkit never imports them.

- :mod:`studies.estimators`, :mod:`studies.estimators_dd`: the figures of docs/estimators.md
- :mod:`studies.pyins_peer`: pyins' feedback filter on a simkit file (needs python-ins), the peer of kf15
- :mod:`studies.evaluate`, :mod:`studies.consistency`: RMS tables from the referee's errors; the filter's own
  error states against truth (for NEES studies)
- :mod:`studies.attitude`, :mod:`studies.attitude_float`, :mod:`studies.atdop`: the tables of docs/attitude.md
- :mod:`studies.ambiguity`, :mod:`studies.ambiguity_problems`: the C-LAMBDA table of docs/ambiguity.md and the
  random ambiguity problems of the tests and benchmarks
"""
