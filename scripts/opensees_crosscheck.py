#!/usr/bin/env python3
"""Single rigid mass on a friction bearing under El Centro 1940 NS (uniform excitation in x).

Model A: flatSliderBearing (Coulomb mu), Model B: singleFPBearing (Coulomb mu, Reff).
Usage: slider_opensees.py flat|fp [--mu 0.05] [--R 2.0] [--dt 0.001] [--uy 1e-6] [--out file.csv]
Prints one JSON line: max_slip_m, residual_slip_m, peak_abs_accel_g, ...
"""
import argparse
import json
import time

import numpy as np
import openseespy.opensees as ops

from opensees_common import settle_under_gravity, start_transient, step

G = 9.80665
import os
REC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "assets", "records", "el_centro_1940_ns.csv")


def load_record(path):
    t, a = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or line.startswith("time"):
                continue
            s = line.strip().split(",")
            if len(s) == 2:
                t.append(float(s[0]))
                a.append(float(s[1]))
    t, a = np.array(t), np.array(a)
    dt = t[1] - t[0]
    assert np.allclose(np.diff(t), dt, atol=1e-9)
    return t, a, dt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model", choices=["flat", "fp"])
    ap.add_argument("--mu", type=float, default=0.05)
    ap.add_argument("--R", type=float, default=2.0)
    ap.add_argument("--dt", type=float, default=0.001)
    ap.add_argument("--uy", type=float, default=1e-6,
                    help="elastic shear deformation at sliding onset, m (kInit = mu*W/uy)")
    ap.add_argument("--tol", type=float, default=1e-12, help="NormDispIncr tolerance, m")
    ap.add_argument("--integrator", default="newmark",
                    help="newmark (average acceleration) | hht:ALPHA | genalpha:RHO_INF")
    ap.add_argument("--betaK", type=float, default=0.0,
                    help="stiffness-proportional (current tangent) Rayleigh damping on the bearing (-doRayleigh)")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()

    t_rec, a_rec_g, dt_rec = load_record(REC)
    T = t_rec[-1]

    m = 1000.0                  # kg
    W = m * G                   # N
    kinit = args.mu * W / args.uy   # N/m, elastic slip before sliding = uy
    kv = 1e4 * W                # N/m, axial (vertical) spring: static settlement 0.1 mm
    kr = 1e9                    # N m/rad, rotational spring

    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.mass(2, m, m, 0.0)

    ops.frictionModel("Coulomb", 1, args.mu)
    ops.uniaxialMaterial("Elastic", 1, kv)   # -P
    ops.uniaxialMaterial("Elastic", 2, kr)   # -Mz
    # local x = global +Y (axial, vertical), local y = global -X (shear)
    orient = ["-orient", 0.0, 1.0, 0.0, -1.0, 0.0, 0.0]
    itr = ["-iter", 100, 1e-12]
    if args.betaK > 0:
        itr += ["-doRayleigh"]
    if args.model == "flat":
        ops.element("flatSliderBearing", 1, 1, 2, 1, kinit, "-P", 1, "-Mz", 2, *orient, *itr)
    else:
        ops.element("singleFPBearing", 1, 1, 2, 1, args.R, kinit, "-P", 1, "-Mz", 2, *orient, *itr)

    # gravity: static, then held constant
    settle_under_gravity(2, W)
    uy_static = ops.nodeDisp(2, 2)

    # uniform excitation in x, accel in m/s^2, linear interpolation of the 0.02 s record
    ops.timeSeries("Path", 2, "-dt", dt_rec, "-values", *a_rec_g.tolist(), "-factor", G)
    ops.pattern("UniformExcitation", 2, 1, "-accel", 2)

    if args.integrator == "newmark":
        integrator = ("Newmark", 0.5, 0.25)
    elif args.integrator.startswith("hht:"):
        integrator = ("HHT", float(args.integrator[4:]))
    elif args.integrator.startswith("genalpha:"):
        r = float(args.integrator[9:])  # Chung-Hulbert parameters from rho_inf
        am, af = (2 * r - 1) / (r + 1), r / (r + 1)
        # OpenSees GeneralizedAlpha(alphaM, alphaF) uses alpha = 1 - (CH alpha)
        integrator = ("GeneralizedAlpha", 1 - am, 1 - af)
    else:
        raise SystemExit("unknown integrator")
    start_transient(args.tol, integrator, args.betaK)

    n = int(round(T / args.dt))
    ts = np.empty(n + 1); u = np.empty(n + 1); aa = np.empty(n + 1); vv = np.empty(n + 1)
    ts[0] = 0.0; u[0] = 0.0; aa[0] = 0.0; vv[0] = 0.0
    ag = lambda tt: G * np.interp(tt, t_rec, a_rec_g)
    fails = 0
    t0 = time.time()
    for i in range(1, n + 1):
        fails += step(args.dt)
        tt = ops.getTime()
        ts[i] = tt
        u[i] = ops.nodeDisp(2, 1)            # relative to fixed node 1 = relative to ground
        vv[i] = ops.nodeVel(2, 1)
        aa[i] = ops.nodeAccel(2, 1) + ag(tt)  # relative + ground = absolute
    wall = time.time() - t0

    k_peak = int(np.argmax(np.abs(u)))
    res = {
        "model": args.model, "mu": args.mu, "R": args.R if args.model == "fp" else None,
        "dt": args.dt, "kInit_N_per_m": kinit, "kInit_over_W_per_m": kinit / W,
        "uy_elastic_m": args.uy, "kv_over_W_per_m": kv / W, "tol": args.tol, "integrator": args.integrator, "betaK": args.betaK,
        "static_settlement_m": uy_static,
        "max_slip_m": float(np.abs(u).max()), "t_max_slip_s": float(ts[k_peak]),
        "signed_peak_slip_m": float(u[k_peak]),
        "max_pos_slip_m": float(u.max()), "max_neg_slip_m": float(u.min()),
        "residual_slip_m": float(u[-1]),
        "peak_abs_accel_g": float(np.abs(aa).max() / G),
        "t_end_s": float(ts[-1]), "substep_retries": fails, "wall_s": wall,
    }
    if args.out:
        np.savetxt(args.out, np.column_stack([ts, u, vv, aa / G]), delimiter=",",
                   header="t_s,slip_m,slip_vel_mps,abs_accel_g", comments="")
    print(json.dumps(res))


if __name__ == "__main__":
    main()
