"""Datasets rendered on a Ray cluster (or in this process).

``python -m alpenglow.dataset render JOB.toml [--address ADDR]`` or::

    from alpenglow import dataset
    dataset.render("job.toml", address=None)   # a new local Ray cluster
    dataset.render("job.toml", local=True)     # one renderer in this process

The job format, resuming, retries and cluster use are documented in
docs/EMBEDDING.md (*Datasets on Ray*). Ray is an optional extra
(``pip install './python[ray]'``); this package imports without it.
"""

from .job import AOVS, Job, JobError, load_job, parse_job
from .runner import FrameEvent, Result, Shard, make_shards, render

__all__ = ["AOVS", "FrameEvent", "Job", "JobError", "Result", "Shard", "load_job", "make_shards", "parse_job", "render"]
