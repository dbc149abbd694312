"""``python -m alpenglow.dataset render JOB.toml [--address ADDR] [--local] [--workers N]``."""

from __future__ import annotations

import argparse
import sys

from .job import JobError
from .runner import render


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m alpenglow.dataset", description="Render a dataset job")
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="render the frames of JOB.toml that are not done yet")
    r.add_argument("job", metavar="JOB.toml")
    r.add_argument("--address", help="Ray cluster address (auto, ray://HOST:10001, HOST:6379); default: a new local cluster")
    r.add_argument("--local", action="store_true", help="render in this process with one renderer, without Ray")
    r.add_argument("--workers", type=int, help="number of Ray actors (overrides ray.workers)")
    r.add_argument("--backend", choices=("auto", "native", "cli"), default="auto", help="renderer backend (default auto)")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    args = parser.parse_args(argv)
    if args.workers is not None and args.workers < 1:
        parser.error(f"--workers: must be at least 1, got {args.workers}")
    if args.local and args.address:
        parser.error("--local and --address exclude each other")
    try:
        result = render(
            args.job,
            args.address,
            local=args.local,
            backend=args.backend,
            workers=args.workers,
            progress=not args.quiet,
        )
    except (JobError, RuntimeError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    print(f"{result.rendered} frames rendered, {result.skipped} already done, {result.total} in the job: {result.out_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
