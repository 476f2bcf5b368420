"""Monte Carlo campaigns on Dask: many runs of a scenario over seeds and parameter grids, restartable, with
per-run metrics (a registry later packages extend) and campaign statistics with confidence intervals.
See docs/campaign.md.

The package is callable: ``simkit.campaign(scenario, out, runs, ...)`` is :func:`run_campaign` (the top-level API),
and ``simkit.campaign.wilson_interval`` and the rest stay reachable, whichever of the two a caller met first
(importing a sub-package rebinds the name ``simkit.campaign`` to it, so a separate function could not keep it)."""
import sys
import types

from .errors import CampaignInputError
from .metrics import DEFAULT_METRICS, evaluate, get, names, register
from .plan import RunSpec, parse_grid, plan
from .runner import dask_client, run_campaign
from .stats import mean_interval, rate, wilson_interval

__all__ = ["CampaignInputError", "DEFAULT_METRICS", "RunSpec", "dask_client", "evaluate", "get", "mean_interval",
           "names", "parse_grid", "plan", "rate", "register", "run_campaign", "wilson_interval"]


class _CallablePackage(types.ModuleType):
    def __call__(self, scenario, out, runs: int, **options) -> dict:
        """:func:`run_campaign`: the summary dict, also written to ``out/summary.json``."""
        return run_campaign(scenario, out, runs, **options)


sys.modules[__name__].__class__ = _CallablePackage
