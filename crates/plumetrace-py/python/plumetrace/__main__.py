"""``python -m plumetrace``: run a scenario, a campaign or list the presets, through the Rust
library (the same outputs as the ``plumetrace`` command line's ``run``, ``campaign`` and
``presets``)."""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional

from . import _api
from ._plumetrace import PlumetraceError, scenario_kind


def _run(args: argparse.Namespace) -> None:
    scenario = args.preset or args.scenario
    if scenario is None:
        raise PlumetraceError("give a scenario file or --preset NAME (see `python -m plumetrace presets`)")
    if args.preset is not None and args.scenario is not None:
        raise PlumetraceError("give a scenario file or --preset, not both")
    kind = scenario_kind(scenario)
    if kind == "plume":
        stats = _api.run_plume(scenario, args.out, seed=args.seed)
        print(f"{stats['scenario']}: simulated {stats['sim_time_s']:.0f} s in "
              f"{stats['wall_s']:.2f} s; wrote {args.out}")
        return
    r = _api.run(scenario, seed=args.seed)
    r.save(args.out)
    print(f"{r.name}: {r.verdict}; outcome {r.outcome}; wrote {args.out}")


def _campaign(args: argparse.Namespace) -> None:
    rep = _api.campaign(args.file, args.out, jobs=args.jobs, seeds=args.seeds,
                        shard=args.shard, progress=not args.quiet)
    print(f"{rep['name']}: ran {rep['ran']}, skipped {rep['skipped']}, failed {rep['failed']} "
          f"of {rep['planned']} runs; wrote {rep['out']}")


def _presets(args: argparse.Namespace) -> None:
    for name, summary in _api.presets():
        print(f"{name:22} {summary}")


def main(argv: Optional[List[str]] = None) -> int:
    """The command line; returns the exit status."""
    ap = argparse.ArgumentParser(prog="python -m plumetrace", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="simulate a scenario and write its outputs")
    r.add_argument("scenario", nargs="?", help="scenario file (TOML); or --preset")
    r.add_argument("--preset", help="built-in scenario (see `presets`)")
    r.add_argument("--seed", type=int, help="run seed (default the scenario's)")
    r.add_argument("--out", default="out", help="output directory (default: out)")
    r.set_defaults(func=_run)
    c = sub.add_parser("campaign", help="run (or resume) a campaign file")
    c.add_argument("file")
    c.add_argument("--out", required=True)
    c.add_argument("--jobs", type=int)
    c.add_argument("--seeds", type=int, help="seeds per group (overrides the file's)")
    c.add_argument("--shard", help="K/N: only every N-th run, from the K-th")
    c.add_argument("--quiet", action="store_true", help="no progress bar")
    c.set_defaults(func=_campaign)
    p = sub.add_parser("presets", help="list the built-in scenarios")
    p.set_defaults(func=_presets)
    args = ap.parse_args(argv)
    try:
        args.func(args)
    except PlumetraceError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
