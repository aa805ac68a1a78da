#!/usr/bin/env python3
"""The paper's two-block model in OpenSees (openseespy), timed: the side-by-side of issue 16.

A base mass M slides on a flatSliderBearing (Coulomb rho; the whole weight (M + m) g goes
through it), a structure mass m sits on a spring k = m (2 pi f)^2 with f = 1 Hz; harmonic
ground acceleration 0.3 g sin(Omega t) from rest, alpha = m/(M + m). Two unknowns of motion
(the masses' x; the bearing's vertical and rotational springs add two more), Newmark
average acceleration, Newton with NormDispIncr 1e-12.

Usage: opensees_two_block.py [--alpha 0.5] [--rho 0.1] [--ratio 1] [--duration 100]
                             [--dt 0.001] [--repeat 3]
Prints one JSON line: us_max_over_d, abase_over_aground, wall_s (median of the repeats),
and how many steps had to be retried in substeps.
Compare: slidebase run --alpha 0.5 --friction 0.1 --freq-ratio 1 --duration 100
         slidebase run … --model mass-spring
"""
import argparse
import json
import math
import statistics
import time

import openseespy.opensees as ops

from opensees_common import settle_under_gravity, start_transient, step

G = 9.80665


def run(args):
    total = 1000.0                    # kg, M + m
    m = args.alpha * total            # structure
    big_m = total - m                 # base
    omega = 2 * math.pi * 1.0         # structure, rad/s
    k = m * omega * omega
    big_omega = args.ratio * omega
    amplitude = 0.3 * G
    weight = total * G
    uy = 1e-6                         # elastic slip before sliding, m
    kinit = args.rho * weight / uy

    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, 0.0)
    ops.node(3, 0.0, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.fix(3, 0, 1, 1)
    ops.mass(2, big_m, big_m, 0.0)
    ops.mass(3, m, 0.0, 0.0)
    ops.frictionModel("Coulomb", 1, args.rho)
    ops.uniaxialMaterial("Elastic", 1, 1e4 * weight)   # bearing axial
    ops.uniaxialMaterial("Elastic", 2, 1e9)            # bearing rotation
    ops.uniaxialMaterial("Elastic", 3, k)              # the structure's spring
    orient = ["-orient", 0.0, 1.0, 0.0, -1.0, 0.0, 0.0]
    ops.element("flatSliderBearing", 1, 1, 2, 1, kinit, "-P", 1, "-Mz", 2, *orient,
                "-iter", 100, 1e-12)
    ops.element("zeroLength", 2, 2, 3, "-mat", 3, "-dir", 1)

    # Gravity through the bearing, then held.
    settle_under_gravity(2, weight)

    # a_g(t) = A sin(Omega t).
    ops.timeSeries("Trig", 2, 0.0, args.duration + 1.0, 2 * math.pi / big_omega,
                   "-factor", amplitude)
    ops.pattern("UniformExcitation", 2, 1, "-accel", 2)
    start_transient(1e-12, ("Newmark", 0.5, 0.25))

    steps = int(round(args.duration / args.dt))
    us_max = 0.0
    abase_max = 0.0
    start = time.perf_counter()
    retries = 0
    for _ in range(steps):
        retries += step(args.dt)
        t = ops.getTime()
        us_max = max(us_max, abs(ops.nodeDisp(2, 1)))
        a_abs = ops.nodeAccel(2, 1) + amplitude * math.sin(big_omega * t)
        abase_max = max(abase_max, abs(a_abs))
    wall = time.perf_counter() - start
    d = amplitude / big_omega ** 2
    return us_max / d, abase_max / amplitude, wall, retries


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--alpha", type=float, default=0.5, help="mass ratio m/(M + m) (0.5)")
    ap.add_argument("--rho", type=float, default=0.1, help="friction coefficient (0.1)")
    ap.add_argument("--ratio", type=float, default=1.0,
                    help="excitation over structure frequency, Omega/omega (1)")
    ap.add_argument("--duration", type=float, default=100.0, help="seconds of motion (100)")
    ap.add_argument("--dt", type=float, default=0.001, help="time step, s (0.001)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="timed runs; the median is printed (3)")
    args = ap.parse_args()
    runs = [run(args) for _ in range(args.repeat)]
    us, ab, _, retries = runs[-1]
    print(json.dumps({
        "us_max_over_d": us,
        "abase_over_aground": ab,
        "wall_s": statistics.median(r[2] for r in runs),
        "steps": int(round(args.duration / args.dt)),
        "steps_retried_in_substeps": retries,
    }))


if __name__ == "__main__":
    main()
