"""The Dask worker plugin of the campaign: it carries the .fmu files as bytes (no
shared filesystem assumed) and, for workers that do not have tailsim, the package
itself as a zip. It depends on the standard library and distributed only, so it
can be pickled by value (cloudpickle) and unpickled on a worker without tailsim;
its setup then makes tailsim importable and installs the FMUs. The scheduler sends
it to every worker, also to one that joins or is restarted later."""

from __future__ import annotations

import hashlib
import importlib
import os
import sys
import tempfile
from collections.abc import Mapping

from distributed import WorkerPlugin


class FmuPlugin(WorkerPlugin):
    name = "tailsim-fmus"
    idempotent = True  # a second registration under the same name is a no-op

    def __init__(self, blobs: Mapping[str, bytes], package_zip: bytes | None = None):
        self.blobs = dict(blobs)
        self.package_zip = package_zip

    def setup(self, worker=None):
        if self.package_zip is not None and "tailsim" not in sys.modules:
            digest = hashlib.sha256(self.package_zip).hexdigest()[:16]
            folder = getattr(worker, "local_directory", None) or tempfile.gettempdir()
            path = os.path.join(folder, f"tailsim-{digest}.zip")
            with open(path + ".tmp", "wb") as f:
                f.write(self.package_zip)
            os.replace(path + ".tmp", path)
            if path not in sys.path:
                sys.path.insert(0, path)
            importlib.invalidate_caches()
        from tailsim.campaign.runner import install_fmus

        install_fmus(self.blobs)

    def teardown(self, worker=None):
        # Called when the worker closes (the plugin is registered once per FMU set).
        try:
            from tailsim.campaign.runner import release_all
        except ImportError:
            return
        release_all()


def make_task():
    """The task of one run, for clusters without tailsim: a closure, so that distributed
    pickles the task graph with cloudpickle (by value: the scheduler, which unpickles
    the graph, needs no tailsim); on a worker the plugin has made tailsim importable."""

    def run_task(job, spec_json, digests):
        from tailsim.campaign.runner import run_job

        return run_job(job, spec_json, digests)

    return run_task
