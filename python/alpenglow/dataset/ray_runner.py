"""The Ray side of :func:`alpenglow.dataset.render`: one actor per GPU, shards fed to idle actors.

Fault tolerance has two layers:

* Ray's own: each actor is created with ``max_restarts`` and
  ``max_task_retries`` (from the job's ``[ray]`` table), so a worker process
  that dies is restarted (its ``__init__`` loads and bakes the scene again)
  and the frames it had in flight are rendered again, transparently.
* The runner's: when an actor is gone for good (its restarts used up, its
  node lost), the frames of its shard that were not committed go back to the
  queue and a new actor takes them; a shard that fails
  ``max_shard_attempts`` times stops the job with the last error.

Frames are committed (files + manifest line) by the driver only, so workers
need no shared file system.
"""

from __future__ import annotations

import collections
import os

from .runner import FrameWorker, Shard, commit

#: Frames submitted to one actor ahead of time (it renders one while the driver stores the last).
_IN_FLIGHT = 2


def _one_line(e: BaseException) -> str:
    text = getattr(e, "cause", None) or e
    lines = [l.strip() for l in str(text).splitlines() if l.strip()]
    line = lines[-1] if lines else type(e).__name__
    # Ray's actor-death messages run on for a paragraph: keep the first sentence.
    first = line.split(". ")[0]
    return first if len(first) <= 200 else first[:197] + "..."


def _default_workers(ray, job) -> int:
    resources = ray.cluster_resources()
    if job.ray["num_gpus"] > 0:
        return max(1, int(resources.get("GPU", 0) // job.ray["num_gpus"]))
    return max(1, int(resources.get("CPU", 1) // max(job.ray["num_cpus"], 1e-9)))


def render_on_ray(job, shards, address, backend, workers, manifest, report, result, on_frame) -> None:
    try:
        import ray
    except ImportError:
        raise RuntimeError(
            "ray is not installed: pip install './python[ray]' (or render with local=True / --local)"
        ) from None
    started_here = False
    if not ray.is_initialized():
        if address is None:
            # A new local cluster: its workers find this package where the driver does.
            package_root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
            path = os.pathsep.join(p for p in (package_root, os.environ.get("PYTHONPATH")) if p)
            ray.init(include_dashboard=False, runtime_env={"env_vars": {"PYTHONPATH": path}})
        else:
            ray.init(address=address)
        started_here = True
    try:
        _schedule(ray, job, shards, backend, workers, manifest, report, result, on_frame)
    finally:
        if started_here:
            ray.shutdown()


def _schedule(ray, job, shards, backend, workers, manifest, report, result, on_frame) -> None:
    cfg = job.ray
    n = workers or cfg["workers"] or _default_workers(ray, job)
    n = max(1, min(n, len(shards)))
    actor_class = ray.remote(
        num_gpus=cfg["num_gpus"],
        num_cpus=cfg["num_cpus"],
        max_restarts=cfg["max_restarts"],
        max_task_retries=cfg["max_task_retries"],
    )(FrameWorker)
    queue = collections.deque(shards)
    attempts = collections.Counter()
    actors: dict[int, object] = {}
    current: dict[int, tuple[Shard, collections.deque]] = {}
    inflight: dict[object, tuple[int, int, int]] = {}  # ref -> (worker, shard, frame)
    next_id = 0

    def start_actor() -> None:
        nonlocal next_id
        actors[next_id] = actor_class.remote(job, backend)
        next_id += 1

    def feed(w: int) -> None:
        while sum(1 for v in inflight.values() if v[0] == w) < _IN_FLIGHT:
            if w not in current or not current[w][1]:
                if w in current and any(v[0] == w for v in inflight.values()):
                    return  # finish this shard's frames in flight before taking another
                current.pop(w, None)
                if not queue:
                    return
                shard = queue.popleft()
                attempts[shard.index] += 1
                current[w] = (shard, collections.deque(shard.frames))
            shard, todo = current[w]
            frame = todo.popleft()
            inflight[actors[w].render_frame.remote(frame)] = (w, shard.index, frame)

    for _ in range(n):
        start_actor()
    result.workers = n
    report.note(f"{len(shards)} shard{'s' * (len(shards) != 1)} on {n} Ray worker{'s' * (n != 1)}")
    try:
        for w in list(actors):
            feed(w)
        while inflight:
            ready, _ = ray.wait(list(inflight), num_returns=1)
            ref = ready[0]
            w, shard_index, frame = inflight.pop(ref)
            try:
                _, files, pid = ray.get(ref)
            except ray.exceptions.RayActorError as e:
                _lost_actor(ray, w, e, job, manifest, actors, current, inflight, queue, attempts, report, result)
                if queue:
                    start_actor()
                    result.workers += 1
                    for other in list(actors):
                        feed(other)
                continue
            except ray.exceptions.RayTaskError as e:
                raise RuntimeError(f"frame {frame}: {_one_line(e)}") from None
            commit(job, manifest, report, result, on_frame, shard_index, w, frame, files, pid)
            if w in actors:
                feed(w)
    finally:
        for handle in actors.values():
            try:
                ray.kill(handle)
            except Exception:  # noqa: BLE001 - already gone
                pass


def _lost_actor(ray, w, error, job, manifest, actors, current, inflight, queue, attempts, report, result) -> None:
    """An actor is gone for good: its shard's uncommitted frames go back to the queue."""
    if w not in actors:
        return
    handle = actors.pop(w)
    try:
        ray.kill(handle, no_restart=True)
    except Exception:  # noqa: BLE001 - already gone
        pass
    for ref in [r for r, v in inflight.items() if v[0] == w]:
        del inflight[ref]
    shard, _ = current.pop(w, (None, None))
    if shard is None:
        return
    frames = tuple(f for f in shard.frames if f not in manifest.done)
    if not frames:
        return
    if attempts[shard.index] >= job.ray["max_shard_attempts"]:
        raise RuntimeError(
            f"shard {shard.index} (frames {shard.frames[0]}..{shard.frames[-1]}) failed {attempts[shard.index]} times "
            f"(ray.max_shard_attempts); last error: {_one_line(error)}"
        )
    result.shard_retries += 1
    report.note(f"worker {w} lost ({_one_line(error)}); shard {shard.index} re-queued with {len(frames)} frames")
    queue.appendleft(Shard(shard.index, frames))
