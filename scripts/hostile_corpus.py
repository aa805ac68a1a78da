#!/usr/bin/env python3
"""The hostile-input corpus: malformed and extreme inputs of every kind, run against the
release binary, each classified as a pass (a clean one-line error, or a finite result
when the input is valid) or a failure (panic, abort, signal, hang, NaN/inf/null in the
JSON, an invalid input accepted, a valid one refused).

    cargo build --release
    python3 scripts/hostile_corpus.py [--bin target/release/slidebase] [--only CATEGORY]

Prints a table by category and every failing case; exits non-zero if any case fails.
The corpus is generated here (seeded), in a temporary folder: scene files and records
mutated from the shipped ones, command-line flags with extreme values, sweep tables,
output paths, FIFOs and devices, huge sizes. Standard library only.
"""

import argparse
import json
import os
import random
import re
import subprocess
import sys
import tempfile
import time
from collections import OrderedDict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 60
MEMORY_LIMIT = 4 << 30

EXTREME = ["0", "-1", "-0.0", "1e-300", "1e300", "-1e300", "nan", "inf", "-inf", "1e-12",
           "1e9", "1e20", "18446744073709551615", "x", "", "0x10", "1,5"]


class Case:
    def __init__(self, category, name, args, expect, stdin=None, check=None, timeout=None):
        self.category = category
        self.name = name
        self.args = args
        self.expect = expect  # "error", "ok" or "any"
        self.check = check  # extra check of a successful run: fn(stdout) -> problem or None
        self.timeout = timeout or TIMEOUT_S


def record_file_cases(tmp, category, ext, table):
    """One `run --record` case per (name, file text) of `table`, written to `tmp`; a
    name containing "valid" must run, every other one must be refused."""
    out = []
    for name, text in table.items():
        path = tmp / ("rec-%s.%s" % (re.sub(r"\W+", "-", name), ext))
        path.write_text(text, encoding="utf-8")
        expect = "ok" if "valid" in name else "error"
        out.append(Case(category, name, ["run", "--record", str(path), "--model", "mass-spring", "--json"], expect))
    return out


def limit_memory():
    try:
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    except (ImportError, ValueError, OSError):
        pass


def json_problem(stdout):
    """A problem with the JSON a run printed, or None."""
    text = stdout.strip().splitlines()[-1] if stdout.strip() else ""
    if re.search(r"\bnull\b|NaN|Infinity", text):
        return "JSON carries null/NaN/inf: " + text[:200]
    try:
        json.loads(text)
    except ValueError:
        return "not one JSON object: " + text[:200]
    return None


def run_case(binary, case, workdir):
    start = time.time()
    try:
        p = subprocess.run([binary] + case.args, capture_output=True, text=True,
                           timeout=case.timeout, cwd=workdir, preexec_fn=limit_memory,
                           errors="replace")
    except subprocess.TimeoutExpired:
        return "FAIL", "hang (no answer in %d s)" % case.timeout, time.time() - start
    elapsed = time.time() - start
    err = p.stderr
    if p.returncode < 0:
        return "FAIL", "killed by signal %d" % -p.returncode, elapsed
    if p.returncode in (101, 134) or "panicked" in err or "memory allocation" in err:
        return "FAIL", "panic/abort: " + err.strip()[-300:], elapsed
    if p.returncode == 0:
        if case.expect == "error":
            return "FAIL", "accepted an invalid input: " + p.stdout.strip()[:200], elapsed
        if "--json" in case.args:
            problem = json_problem(p.stdout)
            if problem:
                return "FAIL", problem, elapsed
        if case.check:
            problem = case.check(p.stdout)
            if problem:
                return "FAIL", problem, elapsed
        return "ok", "finite result", elapsed
    first = next((l for l in err.splitlines() if l.strip()), "")
    if case.expect == "ok":
        return "FAIL", "refused a valid input: " + first[:300], elapsed
    if not first.startswith("error:"):
        return "FAIL", "not a clean error: " + err.strip()[:300], elapsed
    return "ok", "clean error", elapsed


# ---- the corpus ---------------------------------------------------------------------

def scene_mutants(rng, base, count, tmp, stem):
    """Files mutated from a shipped scene (extreme numbers, deleted/duplicated/swapped lines,
    junk, cut-off text)."""
    junk = ["[[block]]", 'name = ""', "vertices = [[0.0, 0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]",
            "vertices = []", "[[contact]]", 'blocks = ["raft", "raft"]', "friction = -1",
            "[structure]", 'base = "ground"', "floors = []", "gravity = 0.0", "[[fixed_point]]",
            'block = "roof"', "point = [1e300, 0.0]", "force = [nan, 0.0]", '"unterminated',
            "= 3", "\ufeff", 'record = "/dev/zero"', "[excitation]\nkind = \"harmonic\""]
    lines0 = base.splitlines()
    paths = []
    for k in range(count):
        lines = list(lines0)
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(lines))
            op = rng.randrange(6)
            if op <= 1:
                nums = list(re.finditer(r"(?<![\w.])-?\d[\d.eE+-]*", lines[i]))
                if nums:
                    m = rng.choice(nums)
                    lines[i] = lines[i][:m.start()] + rng.choice(EXTREME[:13]) + lines[i][m.end():]
            elif op == 2 and len(lines) > 1:
                del lines[i]
            elif op == 3:
                lines.insert(i, lines[i])
            elif op == 4:
                j = rng.randrange(len(lines))
                lines[i], lines[j] = lines[j], lines[i]
            else:
                lines.insert(i, rng.choice(junk))
        text = ("\r\n" if rng.random() < 0.2 else "\n").join(lines)
        if rng.random() < 0.05:
            text = text[: rng.randrange(len(text))]
        path = tmp / ("%s-%03d.toml" % (stem, k))
        path.write_text(text, encoding="utf-8")
        paths.append(path)
    return paths


def scene_cases(rng, tmp):
    tb = (ROOT / "assets/scenes/two-block.toml").read_text()
    ts = (ROOT / "assets/scenes/three-storey.toml").read_text()
    cases = []
    named = OrderedDict([
        ("third coordinate", tb.replace("[[-1.0, 0.0], [1.0, 0.0]", "[[-1.0, 0.0, 7.0], [1.0, 0.0]")),
        ("duplicate pair", tb.replace("[[bolt]]", '[[contact]]\nblocks = ["ground", "raft"]\nfriction = 0.1\n\n[[bolt]]')),
        ("base is ground", ts.replace('base = "base-slab"', 'base = "ground"')),
        ("floors top-down", ts.replace('floors = ["floor-1", "floor-2", "floor-3"]', 'floors = ["floor-3", "floor-2", "floor-1"]')),
        ("roof is raft", tb.replace('roof = "roof"', 'roof = "raft"')),
        ("bolt end 500 m out", tb.replace("[[0.0, 0.25], [0.0, 2.25]]", "[[0.0, 0.25], [500.0, 2.25]]")),
        ("fixed point 300 m out", tb + '\n[[fixed_point]]\nblock = "roof"\npoint = [300.0, 2.25]\n'),
        ("node 400 m out", ts.replace('{ block = "base-slab", point = [11.8, 0.3] }', '{ block = "base-slab", point = [411.8, 0.3] }', 1)),
        ("empty name", tb.replace('name = "roof"', 'name = ""').replace('roof = "roof"', 'roof = ""')),
        ("undeclared overlap", tb.replace("[[-1.0, 2.0], [1.0, 2.0], [1.0, 2.5], [-1.0, 2.5]]", "[[-1.0, 0.2], [1.0, 0.2], [1.0, 0.7], [-1.0, 0.7]]").replace("[[0.0, 0.25], [0.0, 2.25]]", "[[0.0, 0.1], [0.0, 0.6]]")),
        ("density 1e300", ts.replace("density = 1789400.0", "density = 1e300", 1)),
        ("gravity 1e10", tb.replace("gravity = 9.80665", "gravity = 1e10")),
        ("gravity 0", tb.replace("gravity = 9.80665", "gravity = 0.0")),
        ("gravity -1", tb.replace("gravity = 9.80665", "gravity = -1.0")),
        ("NaN bolt", tb.replace("stiffness = 39478.41760435743", "stiffness = nan")),
        ("NaN load", tb + '\n[[point_load]]\nblock = "roof"\npoint = [nan, 2.25]\nforce = [1.0, 0.0]\n'),
        ("NaN fixed penalty", tb + '\n[[fixed_point]]\nblock = "roof"\npoint = [0.0, 2.25]\npenalty = nan\n'),
        ("block 60 km away", tb + '\n[[block]]\nname = "far"\nvertices = [[60000.0, 0.0], [60001.0, 0.0], [60001.0, 1.0], [60000.0, 1.0]]\nmaterial = { density = 1000.0, youngs_modulus = 1.0e12, poisson_ratio = 0.2 }\n'),
        ("clockwise polygon", tb.replace("[[-1.0, 2.0], [1.0, 2.0], [1.0, 2.5], [-1.0, 2.5]]", "[[-1.0, 2.5], [1.0, 2.5], [1.0, 2.0], [-1.0, 2.0]]")),
        ("poisson 0.5", tb.replace("poisson_ratio = 0.2 }", "poisson_ratio = 0.5 }", 1)),
        ("unknown key", tb.replace('name = "two-block"', 'name = "two-block"\nspeed = 3')),
        ("empty file", ""),
        ("binary junk", "\x00\x01\x02"),
        ("BOM + CRLF (valid)", "\ufeff" + tb.replace("\n", "\r\n")),
    ])
    valid = {"BOM + CRLF (valid)"}
    for name, text in named.items():
        path = tmp / ("scene-%s.toml" % re.sub(r"\W+", "-", name))
        path.write_text(text, encoding="utf-8")
        cases.append(Case("scene TOML", name, ["run", "--scene", str(path), "--duration", "0.02", "--json"],
                          "ok" if name in valid else "error"))
    for path in scene_mutants(rng, tb, 150, tmp, "tb") + scene_mutants(rng, ts, 50, tmp, "ts"):
        cases.append(Case("scene TOML", "mutant " + path.name, ["run", "--scene", str(path), "--duration", "0.02", "--json"], "any"))
    return cases


def record_cases(rng, tmp):
    cases = []
    at2 = OrderedDict([
        ("NPTS 1E30", "h\nh\nh\nNPTS= 1E30, DT= 0.01 SEC\n0.1 0.2\n"),
        ("NPTS 1e12", "h\nh\nh\nNPTS= 1000000000000, DT= 0.01 SEC\n" + "0.01 0.02 0.03 0.04 0.05\n" * 200),
        ("NPTS negative", "h\nh\nh\nNPTS= -5, DT= 0.01 SEC\n0.1 0.2\n"),
        ("NPTS fractional", "h\nh\nh\nNPTS= 2.5, DT= 0.01 SEC\n0.1 0.2\n"),
        ("DT 0", "h\nh\nh\nNPTS= 2, DT= 0 SEC\n0.1 0.2\n"),
        ("DT 1e-9", "h\nh\nh\nNPTS= 3, DT= 1e-9 SEC\n0.1 0.2 0.1\n"),
        ("DT 1e-300", "h\nh\nh\nNPTS= 3, DT= 1e-300 SEC\n0.1 0.2 0.1\n"),
        ("DT nan", "h\nh\nh\nNPTS= 3, DT= nan SEC\n0.1 0.2 0.1\n"),
        ("value 1e300 g", "h\nh\nh\nNPTS= 3, DT= .01 SEC\n0.1 1e300 0.1\n"),
        ("value nan", "h\nh\nh\nNPTS= 3, DT= .01 SEC\n0.1 nan 0.1\n"),
        ("too few values", "h\nh\nh\nNPTS= 9, DT= .01 SEC\n0.1 0.2 0.1\n"),
        ("too many values", "h\nh\nh\nNPTS= 2, DT= .01 SEC\n0.1 0.2 0.1\n"),
        ("vertical title", "PEER\nImperial Valley, 1940, El Centro, UP\nG\nNPTS= 3, DT= .01 SEC\n0.1 0.2 0.1\n"),
        ("header only", "h\nh\nh\n"),
        ("empty", ""),
        ("all zero", "h\nh\nh\nNPTS= 4, DT= .01 SEC\n0 0 0 0\n"),
        ("Fortran D, CRLF, BOM (valid)", "\ufeffh\r\nh\r\nh\r\nNPTS= 4, DT= .01 SEC\r\n 1.0D-01 -2.0d-1\t0.1D0 0\r\n\r\n"),
        ("legacy header (valid)", "h\nh\nh\n  4   .01000   NPTS, DT\n0.1 0.2 0.1 0\n"),
    ])
    cases.extend(record_file_cases(tmp, "AT2 record", "at2", at2))
    csv = OrderedDict([
        ("BOM first row (valid)", "\ufeff0.0,0.9\n0.01,0.1\n0.02,0.0\n0.03,0.0\n"),
        ("CRLF tabs header (valid)", "time_s\taccel_g\r\n0\t0.1\r\n0.01\t0.2\r\n0.02\t0.0\r\n\r\n"),
        ("typo first row", "1.0e,0.3\n0.01,0.1\n"),
        ("time decreasing", "0,0.1\n0.02,0.1\n0.01,0.2\n"),
        ("non-uniform", "0,0.1\n0.01,0.1\n0.03,0.2\n"),
        ("starts at 5 s", "5,0.1\n5.01,0.1\n"),
        ("one row", "0,0.1\n"),
        ("three columns", "0,0.1,3\n0.01,0.2,3\n"),
        ("1e300 g", "0,1e300\n0.01,-1e300\n"),
        ("all zero", "0,0\n0.01,0\n0.02,0\n"),
        ("dt 1e-9", "0,0.1\n1e-9,0.2\n2e-9,0.1\n"),
        ("dt 2 s", "0,0.1\n2,0.2\n4,0.1\n"),
        ("nan time", "0,0.1\nnan,0.2\n"),
        ("vertical comment", "# component: UP (vertical)\n0,0.1\n0.01,0.2\n0.02,0.1\n"),
        ("only comments", "# a\n# b\n"),
    ])
    cases.extend(record_file_cases(tmp, "CSV record", "csv", csv))
    # Mutants of a real record.
    lines = (ROOT / "assets/records/el_centro_1940_ns.csv").read_text().splitlines()[:80]
    for k in range(60):
        ls = list(lines)
        for _ in range(rng.randint(1, 3)):
            i = rng.randrange(len(ls))
            op = rng.randrange(4)
            if op == 0:
                ls[i] = re.sub(r"-?\d[\d.eE+-]*$", rng.choice(EXTREME), ls[i])
            elif op == 1:
                del ls[i]
            elif op == 2:
                ls.insert(i, ls[i])
            else:
                ls[i] = ls[i].replace(",", rng.choice([";", "\t", " ", ",,"]))
        path = tmp / ("rec-mutant-%02d.csv" % k)
        path.write_text("\n".join(ls), encoding="utf-8")
        cases.append(Case("CSV record", "mutant %02d" % k, ["run", "--record", str(path), "--json"], "any"))
    return cases


def flag_cases(rng):
    cases = []
    numeric = ["--alpha", "--friction", "--freq-ratio", "--amplitude-g", "--duration", "--dt"]
    # The extreme values that are nevertheless valid (a frictionless joint is physics).
    valid_values = {"--friction": {"0", "-0.0", "1e-300", "1e-12"}}
    for flag in numeric:
        for v in EXTREME:
            args = ["run", flag, v, "--json"]
            if flag != "--duration":
                args += ["--duration", "0.05"]
            expect = "ok" if v in valid_values.get(flag, ()) else "error"
            cases.append(Case("run flags", "%s %s" % (flag, v), args, expect))
    valid = [
        ["run", "--alpha", "0.3", "--friction", "0.05", "--freq-ratio", "2", "--duration", "1", "--json"],
        ["run", "--model", "mass-spring", "--json"],
        ["run", "--record", "el-centro", "--duration", "1", "--json"],
        ["run", "--fixed-base", "--duration", "1", "--json"],
        ["run", "--dt", "0.2", "--duration", "2", "--json"],
        ["run", "--integrator", "trapezoidal", "--duration", "1", "--json"],
        ["run", "--ground", "large-mass", "--duration", "1", "--json"],
        ["run", "--scene", "frame:2", "--duration", "0.5", "--json"],
        ["run", "--scene", "wall:2", "--duration", "0.2", "--json"],
    ]
    for args in valid:
        cases.append(Case("run flags", " ".join(args[1:]), args, "ok"))
    conflicts = [
        ["run", "--record", "el-centro", "--amplitude-g", "0.5"],
        ["run", "--record", "el-centro", "--freq-ratio", "3"],
        ["run", "--friction", "0.3", "--fixed-base"],
        ["run", "--model", "mass-spring", "--dt", "1e-12"],
        ["run", "--model", "mass-spring", "--integrator", "classic"],
        ["run", "--model", "mass-spring", "--ground", "large-mass"],
        ["run", "--model", "mass-spring", "--duration", "1e308"],
        ["run", "--dt", "1e-12"],
        ["run", "--duration", "1e9"],
        ["run", "--dt", "10"],
        ["run", "--record", "el-centro-up"],
        ["run", "--record", "el-centro", "--dt", "0.5"],
        ["run", "--integrator", "hht:5"],
        ["run", "--integrator", "euler"],
        ["run", "--model", "fem"],
        ["run", "--ground", "floating"],
        ["run", "--scene", "frame:0"],
        ["run", "--scene", "frame:101"],
        ["run", "--scene", "wall:x"],
        ["run", "--scene", "nowhere.toml"],
        ["run", "--record", "taft-1952"],
        ["run", "--bogus", "1"],
    ]
    for args in conflicts:
        cases.append(Case("run flags", " ".join(args[1:]), args + ["--json"], "error"))
    return cases


def building_cases():
    cases = []
    bad = [
        ["run", "--scene", "three-storey", "--amplitude-g", "0.5"],
        ["run", "--scene", "three-storey", "--alpha", "0.5"],
        ["run", "--scene", "three-storey", "--freq-ratio", "2"],
        ["run", "--scene", "three-storey", "--model", "mass-spring", "--dt", "5"],
        ["run", "--scene", "three-storey", "--friction", "-1"],
        ["run", "--scene", "three-storey", "--duration", "1e9"],
        ["run", "--scene", "three-storey", "--dt", "1"],
        ["modes", "--scene", "two-block"],
        ["report", "--dt", "0", "--out", "out-report-bad"],
        ["report", "--friction", "nan", "--out", "out-report-bad"],
    ]
    for args in bad:
        cases.append(Case("building commands", " ".join(args), args + (["--json"] if args[0] == "run" else []), "error"))
    good = [
        ["run", "--scene", "three-storey", "--duration", "1", "--json"],
        ["run", "--scene", "three-storey", "--duration", "0.002", "--json"],
        ["run", "--scene", "three-storey", "--model", "mass-spring", "--json"],
        ["run", "--scene", "three-storey", "--ground", "large-mass", "--duration", "0.5", "--json"],
        ["run", "--scene", "frame:6", "--model", "mass-spring", "--duration", "2", "--json"],
        ["modes", "--scene", "three-storey", "--json"],
        ["modes", "--scene", "frame:6", "--json"],
        ["modes", "--scene", "frame:20", "--json"],
    ]
    for args in good:
        cases.append(Case("building commands", " ".join(args), args, "ok",
                          check=json_problem if "--json" in args else None, timeout=120))
    return cases


def sweep_merge_cases(tmp):
    cases = []
    header = ("model,alpha,friction,freq_ratio,us_max_over_d,ur_max_over_d,abase_over_aground,"
              "aroof_over_aground,steps,wall_time_s,energy_residual_rel")
    tables = OrderedDict([
        ("header only", header + "\n"),
        ("empty", ""),
        ("NaN metric", header + "\ndda,0.5,0.1,1,NaN,1,1,1,5,0.1,0\n"),
        ("alpha -5", header + "\ndda,-5,0.1,1,1,1,1,1,5,0.1,0\n"),
        ("unknown model", header + "\nfoo,0.5,0.1,1,1,1,1,1,5,0.1,0\n"),
        ("inf friction", header + "\ndda,0.5,inf,1,1,1,1,1,5,0.1,0\n"),
        ("wrong header", "a,b,c\n1,2,3\n"),
        ("missing column", header.rsplit(",", 1)[0] + "\ndda,0.5,0.1,1,1,1,1,1,5,0.1\n"),
        ("zero steps", header + "\ndda,0.5,0.1,1,1,1,1,1,0,0.1,0\n"),
        ("text in number", header + "\ndda,0.5,0.1,1,x,1,1,1,5,0.1,0\n"),
    ])
    for name, text in tables.items():
        path = tmp / ("sweep-%s.csv" % re.sub(r"\W+", "-", name))
        path.write_text(text, encoding="utf-8")
        cases.append(Case("sweep/merge files", "merge " + name, ["merge", "--out", str(tmp / "merged"), str(path)], "error"))
    good = tmp / "sweep-good.csv"
    good.write_text(header + "\nmass-spring,0.5,0.1,1,3.38,1.13,1,1.13,46,0.01,0\ndda,0.5,0.1,1,3.38,1.13,0.96,1.13,100059,0.3,0.00001\n")
    cases.append(Case("sweep/merge files", "merge valid", ["merge", "--out", str(tmp / "merged-good"), str(good)], "ok"))
    cases.append(Case("sweep/merge files", "merge same file twice", ["merge", "--out", str(tmp / "merged2"), str(good), str(good)], "error"))
    cases.append(Case("sweep/merge files", "merge a FIFO", ["merge", "--out", str(tmp / "m3"), str(tmp / "fifo.csv")], "error"))
    sweep_bad = [
        ["--freq-ratios", "0.1:10:100000000000"], ["--freq-ratios", "0.1:10:1e11"],
        ["--freq-ratios", "0:1:3"], ["--alpha", "1.5"], ["--alpha", ""], ["--friction", "inf"],
        ["--friction", "-1"], ["--amplitude-g", "1e-300"], ["--dt", "10"], ["--duration", "1e9"],
        ["--jobs", "0"], ["--jobs", "100000"], ["--shard", "0/4"], ["--shard", "5/4"],
        ["--shard", "1/18446744073709551615"], ["--integrator", "hht:9"],
    ]
    for extra in sweep_bad:
        cases.append(Case("sweep/merge files", "sweep " + " ".join(x[:40] for x in extra),
                          ["sweep", "--out", str(tmp / "sw-bad")] + extra, "error"))
    cases.append(Case("sweep/merge files", "sweep empty shard",
                      ["sweep", "--alpha", "0.5", "--friction", "0.1", "--freq-ratios", "1", "--duration", "1",
                       "--shard", "3/3", "--out", str(tmp / "shard3")], "ok",
                      check=lambda _: None if (tmp / "shard3/sweep.csv").read_text().startswith("model,") else "empty shard wrote no header"))
    cases.append(Case("sweep/merge files", "sweep small valid",
                      ["sweep", "--alpha", "0.5", "--friction", "0.1", "--freq-ratios", "0.5,2", "--duration", "2",
                       "--out", str(tmp / "sw-ok")], "ok"))
    return cases


def output_cases(tmp):
    afile = tmp / "afile"
    afile.write_text("")
    cases = []
    for cmd in (["run", "--duration", "0.1"], ["sweep", "--alpha", "0.5", "--friction", "0.1", "--freq-ratios", "1", "--duration", "1"],
                ["stability", "--quick"], ["accuracy", "--quick"], ["report", "--duration", "1"],
                ["bench", "--quick", "--no-sweep", "--no-scaling"], ["merge", str(tmp / "sweep-good.csv")]):
        for out, name in ((str(afile), "a file"), ("/proc/nope/x", "uncreatable"), ("/dev/null", "a device")):
            cases.append(Case("output paths", "%s --out %s" % (cmd[0], name), cmd + ["--out", out], "error", timeout=30))
    blocked = tmp / "blocked"
    (blocked / "summary.json").mkdir(parents=True, exist_ok=True)
    cases.append(Case("output paths", "run --out with summary.json a folder", ["run", "--duration", "0.1", "--out", str(blocked)], "error",
                      check=None))
    cases.append(Case("output paths", "run --out valid", ["run", "--duration", "0.1", "--out", str(tmp / "run-ok")], "ok",
                      check=lambda _: None if (tmp / "run-ok/summary.json").exists() else "no summary.json"))
    return cases


def special_file_cases(tmp):
    fifo = tmp / "fifo.csv"
    try:
        os.mkfifo(fifo)
    except (OSError, AttributeError):
        pass
    cases = []
    for path in ("/dev/zero", "/dev/urandom", "/dev/null", str(fifo), str(tmp), "/proc/self/status", "/etc/shadow-nonexistent"):
        cases.append(Case("FIFOs/devices", "record " + path, ["run", "--record", path, "--json"], "error", timeout=20))
        cases.append(Case("FIFOs/devices", "scene " + path, ["run", "--scene", path, "--json"], "error", timeout=20))
    return cases


def huge_cases(tmp):
    cases = []
    big = tmp / "big-scene.toml"
    big.write_text("#" * ((16 << 20) + 10))
    cases.append(Case("huge sizes", "17 MB scene file", ["run", "--scene", str(big)], "error"))
    n = 200000
    import math
    pts = ", ".join("[%.9f, %.9f]" % (0.5 * math.cos(2 * math.pi * k / n), 1.0 + 0.5 * math.sin(2 * math.pi * k / n)) for k in range(n))
    tb = (ROOT / "assets/scenes/two-block.toml").read_text()
    poly = tmp / "poly-200000.toml"
    poly.write_text(tb.replace("[[-1.0, 2.0], [1.0, 2.0], [1.0, 2.5], [-1.0, 2.5]]", "[" + pts + "]"))
    cases.append(Case("huge sizes", "200 000-vertex polygon", ["run", "--scene", str(poly)], "error"))
    blocks = ["[[block]]\nname = \"b%d\"\nvertices = [[%d.0, 0.0], [%d.5, 0.0], [%d.5, 0.5], [%d.0, 0.5]]\nmaterial = { density = 1000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }\n" % (k, k, k, k, k) for k in range(10001)]
    many = tmp / "many-blocks.toml"
    many.write_text('name = "many"\n' + "\n".join(blocks) + '\n[ground]\nblock = "b0"\n')
    cases.append(Case("huge sizes", "10 001 blocks", ["run", "--scene", str(many)], "error"))
    rec = tmp / "rec-11M.csv"
    with open(rec, "w") as f:
        f.write("".join("%g,0.1\n" % (k * 0.01) for k in range(10_000_001)))
    cases.append(Case("huge sizes", "record of 10 000 001 samples", ["run", "--record", str(rec), "--model", "mass-spring"], "error"))
    for args in (["bench", "--repeat", "18446744073709551615"], ["run", "--duration", "1e308"],
                 ["run", "--dt", "5e-324"], ["render", "--width", "100000", "--height", "100000"],
                 ["render", "--width", "0"], ["sweep", "--freq-ratios", "0.1:10:100001"],
                 ["run", "--scene", "wall:100000"], ["run", "--scene", "frame:18446744073709551616"]):
        cases.append(Case("huge sizes", " ".join(args), args, "error"))
    return cases


def other_cases():
    cases = []
    for args in (["bench", "--quick", "--repeat", "0"], ["bench", "--jobs", "0"], ["render", "--exaggeration", "nan"],
                 ["render", "--time", "-1"], ["render", "--friction", "-1"], ["render", "--record", "/dev/zero"],
                 ["nonsense"], ["run", "--help-me"], ["list", "extra"]):
        cases.append(Case("other commands", " ".join(args), args, "error"))
    cases.append(Case("other commands", "list", ["list"], "ok"))
    return cases


def build_corpus(tmp, seed):
    rng = random.Random(seed)
    corpus = (special_file_cases(tmp) + scene_cases(rng, tmp) + record_cases(rng, tmp) + flag_cases(rng)
              + building_cases() + sweep_merge_cases(tmp) + output_cases(tmp) + huge_cases(tmp) + other_cases())
    return corpus


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "target/release/slidebase"))
    ap.add_argument("--only", help="run only this category")
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--timeout", type=float, default=TIMEOUT_S, help="seconds before a case counts as a hang")
    args = ap.parse_args()
    binary = str(Path(args.bin).resolve())
    with tempfile.TemporaryDirectory(prefix="slidebase-corpus-") as d:
        tmp = Path(d)
        corpus = build_corpus(tmp, args.seed)
        if args.only:
            corpus = [c for c in corpus if c.category == args.only]
        table = OrderedDict()
        failures = []
        start = time.time()
        for case in corpus:
            case.timeout = min(case.timeout, args.timeout)
            verdict, why, elapsed = run_case(binary, case, tmp)
            row = table.setdefault(case.category, {"cases": 0, "errors": 0, "results": 0, "fail": 0, "time": 0.0})
            row["cases"] += 1
            row["time"] += elapsed
            if verdict == "FAIL":
                row["fail"] += 1
                failures.append((case, why))
            elif why == "clean error":
                row["errors"] += 1
            else:
                row["results"] += 1
        print("| category | cases | clean error | finite result | failed | time (s) |")
        print("|---|---:|---:|---:|---:|---:|")
        total = {"cases": 0, "errors": 0, "results": 0, "fail": 0, "time": 0.0}
        for cat, row in table.items():
            print("| %s | %d | %d | %d | %d | %.1f |" % (cat, row["cases"], row["errors"], row["results"], row["fail"], row["time"]))
            for k in total:
                total[k] += row[k]
        print("| **all** | %d | %d | %d | %d | %.1f |" % (total["cases"], total["errors"], total["results"], total["fail"], total["time"]))
        print("\n%d cases in %.0f s" % (len(corpus), time.time() - start))
        for case, why in failures:
            print("FAIL [%s] %s: %s\n     args: %s" % (case.category, case.name, why, " ".join(case.args)[:300]))
        sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
