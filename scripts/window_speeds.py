#!/usr/bin/env python3
"""The visualizer's simulation speeds over repeated launches, with their medians.

Issue 16's window target ("the default scene >= 30x real time while rendering") is a
median of repeats, like every other target; one launch of the window check is one
sample, and this machine's speed moves by up to +-50 % from one hour to the next. This
launches the window check (SLIDEBASE_EXIT_AFTER) N times under Xvfb and prints each
launch's three speeds (the first run, while the window starts; the friction changed,
the fixed base played back; both models computed again), the frame time, and the median
of each.

    python3 scripts/window_speeds.py [--repeat 5] [--bin target/release/slidebase]
                                     [--size 1600x900] [--seconds 20] [--json]

Needs xvfb-run and Mesa's software Vulkan (mesa-vulkan-drivers); see .ci/run.
"""

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys

SPEEDS = {
    "first_run": r"first run ([0-9.]+)×",
    "friction_changed": r"friction changed ([0-9.]+)×",
    "both_again": r"both models again ([0-9.]+)×",
    "frame_ms": r"frame time ([0-9.]+) ms",
}


def positive_int(text):
    value = int(text)
    if not 1 <= value <= 100:
        raise argparse.ArgumentTypeError(f"{text}: give 1 to 100 launches")
    return value


def seconds(text):
    value = int(text)
    if not 5 <= value <= 120:
        raise argparse.ArgumentTypeError(f"{text}: give 5 to 120 seconds")
    return value


def window_size(text):
    if not re.fullmatch(r"[1-9][0-9]{2,3}x[1-9][0-9]{2,3}", text):
        raise argparse.ArgumentTypeError(f"{text}: give WIDTHxHEIGHT, e.g. 1600x900")
    return text


def one_launch(binary, size, seconds):
    """One window check; returns its speeds, or raises with what it printed."""
    env = {"SLIDEBASE_EXIT_AFTER": str(seconds)}
    command = ["xvfb-run", "-a", "-s", f"-screen 0 {size}x24", binary]
    done = subprocess.run(
        command,
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=seconds + 100,
    )
    line = next((l for l in done.stdout.splitlines() if l.startswith("frame time")), None)
    if line is None:
        raise RuntimeError(
            f"the window check printed no speeds (exit {done.returncode}):\n"
            f"{done.stdout[-800:]}{done.stderr[-800:]}"
        )
    found = {}
    for key, pattern in SPEEDS.items():
        match = re.search(pattern, line)
        # A run that did not finish within the check is reported "unfinished".
        found[key] = float(match.group(1)) if match else None
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=positive_int, default=5,
                        help="launches of the window (1 to 100, default 5)")
    parser.add_argument("--bin", default="target/release/slidebase",
                        help="the slidebase binary (default target/release/slidebase)")
    parser.add_argument("--size", type=window_size, default="1600x900",
                        help="Xvfb screen WIDTHxHEIGHT (default 1600x900, as CI's)")
    parser.add_argument("--seconds", type=seconds, default=20,
                        help="how long each window stays open (5 to 120, default 20; "
                             "the three runs need ~5 s on this machine)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    if shutil.which("xvfb-run") is None:
        sys.exit("window_speeds: xvfb-run is not installed (apt install xvfb)")
    if shutil.which(args.bin) is None:
        sys.exit(f"window_speeds: --bin {args.bin}: no such executable "
                 "(build it with `cargo build --release`)")
    launches = []
    for i in range(args.repeat):
        speeds = one_launch(args.bin, args.size, args.seconds)
        launches.append(speeds)
        if not args.json:
            shown = ", ".join(
                f"{k} {'unfinished' if v is None else v}" for k, v in speeds.items()
            )
            print(f"launch {i + 1}/{args.repeat}: {shown}", flush=True)
    medians, finished = {}, {}
    for key in SPEEDS:
        # A run still unfinished when the window closed has no speed: it is left out of
        # the median, and the count of those that had one is said.
        values = [l[key] for l in launches if l[key] is not None]
        medians[key] = statistics.median(values) if values else None
        finished[key] = len(values)
    if args.json:
        print(json.dumps({"size": args.size, "launches": launches, "medians": medians,
                          "finished": finished}))
    else:
        print("medians: " + ", ".join(
            f"{k} {v} (of {finished[k]})" if finished[k] < args.repeat else f"{k} {v}"
            for k, v in medians.items()))
        first = medians["first_run"]
        if first is not None:
            verdict = "met" if first >= 30.0 else "missed"
            print(f"target (first run >= 30x, median of the {finished['first_run']} "
                  f"launches of {args.repeat} whose first run finished): {verdict}")


if __name__ == "__main__":
    main()
