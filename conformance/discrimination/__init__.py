"""The kit judged: how well its checks tell right from wrong. ``verdicts`` (a sync through the checks
in a process of its own), ``kill_matrix`` (every wrong sync through every check), ``mutants``
(machine-made wrong syncs), ``tolerance_use`` (how much of each tolerance right syncs use),
``precision`` (false alarms over random draws), ``side_by_side`` (two syncs' drawings of one run) and
``forked`` (a pytest run forked from the app server).
Imports ``apps``, ``checks`` and below (internal; the commands are their face)."""
