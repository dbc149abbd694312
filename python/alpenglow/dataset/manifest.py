"""Atomic output files and the manifest of finished frames.

A frame counts as done only once every one of its files has been written
atomically (temporary file, fsync, rename, fsync of the folder) *and* its line
has been appended (and fsynced) to ``manifest.jsonl`` in the output folder.
A crash at any point leaves at worst a temporary file (removed by the next
run) or a frame that is rendered again; never a half-written file under its
final name, never a frame marked done whose files are missing.
"""

from __future__ import annotations

import hashlib
import json
import os

from .job import Job, JobError

MANIFEST = "manifest.jsonl"
_TMP_MARK = ".tmp-ag-"


def _fsync_dir(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_atomically(path: str, data: bytes) -> None:
    """Writes `data` to `path` so that readers see the old file or the whole new one."""
    folder = os.path.dirname(path) or "."
    os.makedirs(folder, exist_ok=True)
    tmp = os.path.join(folder, f".{os.path.basename(path)}{_TMP_MARK}{os.getpid()}")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    _fsync_dir(folder)


def remove_stale_temporaries(out_dir: str) -> int:
    """Removes temporary files an interrupted run left behind; returns how many."""
    removed = 0
    for root, _, names in os.walk(out_dir):
        for name in names:
            if _TMP_MARK in name:
                os.unlink(os.path.join(root, name))
                removed += 1
    return removed


class Manifest:
    """``manifest.jsonl``: a header line (the job's fingerprint) then one line per finished frame.

    Only the driver writes it (one writer, appends only). A torn last line
    (a crash mid-append) is ignored, so that frame is rendered again.
    """

    def __init__(self, job: Job):
        self.job = job
        self.path = os.path.join(job.out_dir, MANIFEST)
        self.done: dict[int, dict[str, str]] = {}
        self._file = None

    def load(self) -> None:
        """Reads what earlier runs finished; refuses a folder holding another job."""
        fingerprint = self.job.fingerprint()
        if not os.path.exists(self.path):
            return
        with open(self.path, "rb") as f:
            lines = f.read().split(b"\n")
        good = []
        for k, line in enumerate(lines):
            try:
                entry = json.loads(line)
            except ValueError:
                if k >= len(lines) - 2:  # torn last line of an interrupted append
                    continue
                raise JobError(f"{self.path}: line {k + 1} is not JSON: the manifest is damaged (delete it to start over)") from None
            good.append(entry)
        if not good:
            return
        head = good[0]
        if head.get("job") != fingerprint:
            raise JobError(
                f"{self.job.source}: output.dir: {self.job.out_dir} holds the frames of a different job "
                f"(manifest fingerprint {head.get('job')}, this job {fingerprint}); choose another output.dir or delete that folder"
            )
        for entry in good[1:]:
            frame, files = entry.get("frame"), entry.get("files", {})
            if not isinstance(frame, int):
                continue
            # A frame counts only if each of its files is still there with its size.
            if all(
                os.path.getsize(p) == size if os.path.exists(p := os.path.join(self.job.out_dir, rel)) else False
                for rel, (size, _) in files.items()
            ) and {rel for _, _, rel in self.job.files(frame)} == set(files):
                self.done[frame] = files

    def open(self) -> None:
        os.makedirs(self.job.out_dir, exist_ok=True)
        fresh = not os.path.exists(self.path) or os.path.getsize(self.path) == 0
        if not fresh:
            # Cut a torn last line so the next append starts on a line of its own.
            with open(self.path, "rb+") as f:
                data = f.read()
                if not data.endswith(b"\n"):
                    f.truncate(data.rfind(b"\n") + 1)
        self._file = open(self.path, "ab")
        if fresh:
            self._append({"job": self.job.fingerprint(), "version": 1, "source": self.job.source})
            _fsync_dir(self.job.out_dir)

    def _append(self, entry: dict) -> None:
        self._file.write(json.dumps(entry, sort_keys=True).encode() + b"\n")
        self._file.flush()
        os.fsync(self._file.fileno())

    def commit(self, frame: int, files: dict[str, bytes]) -> dict[str, tuple[int, str]]:
        """Writes a frame's files atomically, then records the frame as done."""
        record = {}
        for rel, data in sorted(files.items()):
            write_atomically(os.path.join(self.job.out_dir, rel), data)
            record[rel] = (len(data), hashlib.sha256(data).hexdigest())
        self._append({"frame": frame, "files": record})
        self.done[frame] = record
        return record

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None
