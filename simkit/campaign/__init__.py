"""Monte Carlo campaigns on Dask: many runs of a scenario over seeds and parameter grids, restartable, with
per-run metrics (a registry later packages extend) and campaign statistics with confidence intervals.
See docs/campaign.md."""
from .errors import CampaignInputError
from .metrics import DEFAULT_METRICS, evaluate, get, names, register
from .plan import RunSpec, parse_grid, plan
from .runner import dask_client, run_campaign
from .stats import mean_interval, rate, wilson_interval

__all__ = ["CampaignInputError", "DEFAULT_METRICS", "RunSpec", "dask_client", "evaluate", "get", "mean_interval",
           "names", "parse_grid", "plan", "rate", "register", "run_campaign", "wilson_interval"]
