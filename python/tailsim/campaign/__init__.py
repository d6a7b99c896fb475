"""The Monte-Carlo campaign on a Dask cluster: sampling (`sampling`), one run on a
worker (`runner`, through `tailsim.masters`), the worker plugin (`plugin`), the driver
and its result store (`driver`, `python -m tailsim.campaign`), the statistics report
(`report`), the comparison report's section (`section`) and the native cross-check
(`native`)."""

from .driver import Store, deterministic, local_cluster, main, run_campaign

__all__ = ["Store", "deterministic", "local_cluster", "main", "run_campaign"]
