#!/usr/bin/env python3
"""Two slidebase binaries timed side by side on the same run: the median of their ratios.

This machine's speed moves by up to +-50 % from one hour to the next, so two bench runs
taken apart say little about a change. Runs of the old and the new binary alternated in
the same minutes do: each pair sees the same load, and the median of the pairs' ratios
(new / old) is the change. Both binaries must also agree on the run's results (compare
them with scripts/reference_runs.sh); this only times them.

    python3 scripts/paired_timing.py --base OLD --new NEW [--repeat 9] -- RUN_ARGS...

RUN_ARGS are `slidebase run` arguments (`--json` is added); the time compared is the
run's own `wall_time_s` (the solve, not the process start). Example:

    python3 scripts/paired_timing.py --base /tmp/slidebase-old \\
        --new target/release/slidebase -- --scene three-storey
"""

import argparse
import json
import shutil
import statistics
import subprocess
import sys


SHORT_RUN_S = 0.1


def repeats(text):
    value = int(text)
    if not 1 <= value <= 200:
        raise argparse.ArgumentTypeError(f"{text}: give 1 to 200 pairs")
    return value


def wall_time(binary, run_args):
    """The run's wall_time_s, or exits with what the binary said."""
    done = subprocess.run(
        [binary, "run", "--json", *run_args], capture_output=True, text=True
    )
    if done.returncode != 0:
        sys.exit(f"paired_timing: {binary} run {' '.join(run_args)} failed "
                 f"(exit {done.returncode}):\n{done.stderr.strip()[-800:]}")
    try:
        return float(json.loads(done.stdout)["wall_time_s"])
    except (ValueError, KeyError) as e:
        sys.exit(f"paired_timing: {binary}: no wall_time_s in its JSON ({e})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", required=True, help="the binary before the change")
    parser.add_argument("--new", required=True, help="the binary after the change")
    parser.add_argument("--repeat", type=repeats, default=9,
                        help="pairs of runs (1 to 200, default 9)")
    parser.add_argument("run_args", nargs=argparse.REMAINDER,
                        help="-- then the `slidebase run` arguments")
    args = parser.parse_args()
    run_args = args.run_args[1:] if args.run_args[:1] == ["--"] else args.run_args
    if "--json" in run_args:
        run_args.remove("--json")
    for flag, binary in (("--base", args.base), ("--new", args.new)):
        if shutil.which(binary) is None:
            sys.exit(f"paired_timing: {flag} {binary}: no such executable")
    base_times, new_times, ratios = [], [], []
    for i in range(args.repeat):
        # Alternate which goes first: a run warms the caches and the clock for the next.
        if i % 2 == 0:
            b = wall_time(args.base, run_args)
            n = wall_time(args.new, run_args)
        else:
            n = wall_time(args.new, run_args)
            b = wall_time(args.base, run_args)
        base_times.append(b)
        new_times.append(n)
        ratios.append(n / b)
        print(f"pair {i + 1}/{args.repeat}: base {b:.4f} s, new {n:.4f} s, "
              f"ratio {n / b:.3f}", flush=True)
    print(f"median base {statistics.median(base_times):.4f} s, "
          f"median new {statistics.median(new_times):.4f} s; "
          f"median ratio new/base {statistics.median(ratios):.3f} "
          f"(min {min(ratios):.3f}, max {max(ratios):.3f}, {args.repeat} pairs)", flush=True)
    # A binary timed against itself on 20 ms runs read 0.94 in three pairs: below a
    # tenth of a second the clock's and the scheduler's noise is the size of the changes
    # worth measuring.
    if statistics.median(base_times) < SHORT_RUN_S:
        print(f"note: runs under {SHORT_RUN_S} s are too short to time a change of a few "
              "per cent; give a longer --duration (or more pairs)", file=sys.stderr)


if __name__ == "__main__":
    main()
