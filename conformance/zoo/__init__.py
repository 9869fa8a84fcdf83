"""The zoo: every model pyBullet ships, made into whole right programs in the styles users write them, and
each judged by app mode (issue 47).

App mode promises that a right program passes and a wrong one fails, whatever the user loads. The kit's
own example apps cannot show that: they are the programs it was tuned on. The zoo makes the population
the test: :mod:`~conformance.zoo.models` lists and surveys the model files of ``pybullet_data`` (what
loads, what moves, what there is to draw), :mod:`~conformance.zoo.styles` names the ways users draw them,
:mod:`~conformance.zoo.programs` writes the program of one model in one style for one FURY, and
:mod:`~conformance.zoo.zoo_checks` is the pytest module that judges each (parametrized by model and style,
so a run spreads over cores with xdist and over CI jobs with ``--shard``); :mod:`~conformance.zoo.table`
turns its verdicts into the table of ``docs/zoo-*.md``. ``python -m conformance zoo`` runs it all.
"""

from __future__ import annotations

from conformance.zoo.models import Model, population, survey
from conformance.zoo.styles import STYLES, Style, applicable

__all__ = ["STYLES", "Model", "Style", "applicable", "population", "survey"]
