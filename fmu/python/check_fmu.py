#!/usr/bin/env python3
"""The FMU checked by a real importer (FMPy), as `cargo xtask test` runs it.

1. `fmpy.validate_fmu` finds no problem in the FMU;
2. a temperature step and a ramp, driven through FMPy (two instances in one
   process, stepped in turn), give the trajectory `compensator step
   --precision f32` wrote for the same parameter file (the CSV files given),
   within 1e-6 of the stroke (x) and of the pressure drop (p_a, p_b);
   each tick's temperature is the ramp's value at the tick's midpoint, as
   the CLI sets it;
3. a state saved with getFMUState / serializeFMUState and restored replays
   the same trajectory; reset returns to the start;
4. an invalid parameter is refused at once with a logged message naming
   the field, and the instance ends cleanly; an invalid parameter passed to
   `fmpy.simulate_fmu` fails the simulation with an exception, not a crash;
5. for each `--grid H CSV`: the step with communication steps of H (not
   whole ticks: sub-tick, between two counts) gives the CLI's run on the
   same grid (`--dt H/ceil(H/tick)`, a row every H) within 1e-6;
6. a variable sequence of communication steps follows the reference
   solver (`--reference-csv`, sampled finely) within 0.5 % of the step (the
   f32 twin's goal); a negative step is refused;
7. the archive carries a binary for each of `--platforms`.

Usage: check_fmu.py FMU --step-csv F --ramp-csv F --from C --to C --ramp C_PER_S
       [--grid H CSV]... [--reference-csv F] [--platforms LIST]
Ends with `fmu check: N passed, M failed`; exit status 1 if any failed.
"""

import argparse
import bisect
import csv
import sys
import zipfile

import fmpy
from fmpy.validation import validate_fmu
from fmpy import extract, read_model_description

TOLERANCE = 1e-6

checks = []


def check(name, ok, detail=""):
    checks.append(ok)
    print(f"{'ok  ' if ok else 'FAIL'} {name}{': ' + detail if detail else ''}", flush=True)


def read_cli(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [(float(r["time_s"]), float(r["x_m"]), float(r["p_a_pa"]), float(r["p_b_pa"])) for r in rows]


class Slave:
    """One FMU instance through FMPy's low-level classes, either version."""

    def __init__(self, md, unzipdir, name, logged):
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.v3 = md.fmiVersion.startswith("3")
        self.logged = logged
        if self.v3:
            from fmpy.fmi3 import FMU3Slave

            self.s = FMU3Slave(guid=md.instantiationToken, unzipDirectory=unzipdir,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)

            def log(env, status, category, message):
                logged.append(message.decode())

            self.s.instantiate(logMessage=log)
        else:
            from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

            self.s = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)

            def log(env, instance, status, category, message):
                # The FMU passes its message as the format string, '%' doubled.
                logged.append(message.decode().replace("%%", "%"))

            callbacks = fmi2CallbackFunctions()
            callbacks.logger = fmi2CallbackLoggerTYPE(log)
            self.callbacks = callbacks
            self.s.instantiate(callbacks=callbacks)

    def set(self, name, value):
        if self.v3:
            self.s.setFloat64([self.vr[name]], [value])
        else:
            self.s.setReal([self.vr[name]], [value])

    def get(self, *names):
        vrs = [self.vr[n] for n in names]
        return self.s.getFloat64(vrs) if self.v3 else self.s.getReal(vrs)

    def flags(self):
        vr = [self.vr["flags"]]
        return (self.s.getInt32(vr) if self.v3 else self.s.getInteger(vr))[0]

    def initialize(self, t_oil):
        self.set("T_oil", t_oil)
        if self.v3:
            self.s.enterInitializationMode(startTime=0.0)
        else:
            self.s.setupExperiment(startTime=0.0)
            self.s.enterInitializationMode()
        self.s.exitInitializationMode()

    def step(self, t, h):
        self.s.doStep(currentCommunicationPoint=t, communicationStepSize=h)

    def free(self):
        self.s.terminate()
        self.s.freeInstance()


def ramp_temperature(t, t_from, t_to, rate):
    """`Profile::Ramp::temperature` of the reference (the CLI's profile)."""
    span = abs(t_to - t_from) / rate
    return t_to if t >= span else t_from + (t_to - t_from) * (max(t, 0.0) / span)


def deviation(rows, got, stroke, dp):
    """Largest deviation of x (per stroke) and of p_a, p_b (per dp)."""
    dx = max(abs(a[1] - b[0]) for a, b in zip(rows[1:], got)) / stroke
    dpr = max(max(abs(a[2] - b[1]), abs(a[3] - b[2])) for a, b in zip(rows[1:], got)) / dp
    return dx, dpr


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("--step-csv", required=True)
    ap.add_argument("--ramp-csv", required=True)
    ap.add_argument("--from", dest="t_from", type=float, required=True)
    ap.add_argument("--to", dest="t_to", type=float, required=True)
    ap.add_argument("--ramp", type=float, required=True)
    ap.add_argument("--grid", nargs=2, action="append", default=[], metavar=("H", "CSV"))
    ap.add_argument("--reference-csv")
    ap.add_argument("--platforms")
    args = ap.parse_args()

    problems = validate_fmu(args.fmu)
    check("fmpy.validate_fmu finds no problem", not problems, "; ".join(problems))

    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    tick = float(md.defaultExperiment.stepSize)
    print(f"FMI {md.fmiVersion}, tick {tick} s", flush=True)

    step_rows, ramp_rows = read_cli(args.step_csv), read_cli(args.ramp_csv)
    n = min(len(step_rows), len(ramp_rows)) - 1
    logged = []
    a = Slave(md, unzipdir, "step", logged)
    b = Slave(md, unzipdir, "ramp", logged)
    stroke, dp = a.get("plunger.stroke", "operating.pressure_drop")
    a.initialize(args.t_from)
    b.initialize(args.t_from)
    got_a, got_b = [], []
    state = None
    for k in range(n):
        t = k * tick
        a.set("T_oil", args.t_to)
        b.set("T_oil", ramp_temperature((k + 0.5) * tick, args.t_from, args.t_to, args.ramp))
        a.step(t, tick)
        b.step(t, tick)
        got_a.append(a.get("x", "p_a", "p_b"))
        got_b.append(b.get("x", "p_a", "p_b"))
        if k == n // 2 - 1:
            state = b.s.getFMUState()
            serialized = b.s.serializeFMUState(state)
    for name, rows, got in [("step", step_rows, got_a), ("ramp", ramp_rows, got_b)]:
        dx, dpr = deviation(rows, got, stroke, dp)
        check(f"{name} {args.t_from} -> {args.t_to} C, {n} ticks, against compensator step --precision f32",
              dx <= TOLERANCE and dpr <= TOLERANCE,
              f"max |dx| {dx:.2e} of the stroke, max |dp| {dpr:.2e} of dp")
    moved = abs(got_a[-1][0] - got_a[0][0]) / stroke
    check("the step moves the plunger", moved > 1e-3, f"{moved:.3f} of the stroke")

    # Roll back half way and replay: the same second half, bit for bit.
    b.s.setFMUState(state)
    replay = []
    for k in range(n // 2, n):
        b.set("T_oil", ramp_temperature((k + 0.5) * tick, args.t_from, args.t_to, args.ramp))
        b.step(k * tick, tick)
        replay.append(b.get("x", "p_a", "p_b"))
    check("getFMUState / setFMUState replays the ramp exactly", replay == got_b[n // 2:])
    restored = b.s.deserializeFMUState(serialized)
    b.s.setFMUState(restored)
    again = []
    for k in range(n // 2, n):
        b.set("T_oil", ramp_temperature((k + 0.5) * tick, args.t_from, args.t_to, args.ramp))
        b.step(k * tick, tick)
        again.append(b.get("x", "p_a", "p_b"))
    check(f"a serialized state ({len(serialized)} bytes) replays the ramp exactly", again == got_b[n // 2:])

    # A negative step: refused (Discard), logged, nothing done.
    before = b.get("x")
    try:
        b.step(n * tick, -0.5 * tick)
        refused = False
    except Exception:
        refused = True
    check("a negative step is refused with a logged message",
          refused and b.get("x") == before and any("positive and finite" in m for m in logged))

    # A value reference read as another type: the message names the
    # version's type (FMI 2.0 Integer, FMI 3.0 Int32).
    logged.clear()
    try:
        (b.s.getInt32 if b.v3 else b.s.getInteger)([b.vr["x"]])
        refused = False
    except Exception:
        refused = True
    want = "not an Int32" if b.v3 else "not an Integer"
    check(f"a Float read as an integer is refused in the version's words ('{want}')",
          refused and any(want in m for m in logged), " | ".join(logged))

    b.s.reset()
    b.initialize(args.t_from)
    check("reset returns to the start", b.get("x", "p_a", "p_b") == a_start(md, unzipdir, args.t_from))
    a.free()
    b.free()

    # An invalid parameter: refused at once, naming the field.
    logged.clear()
    c = Slave(md, unzipdir, "bad", logged)
    try:
        c.set("plunger.stroke", -1.0)
        refused = False
    except Exception:
        refused = True
    check("an invalid parameter is refused, the message naming the field",
          refused and any(m.startswith("plunger.stroke") for m in logged), " | ".join(logged))
    c.s.freeInstance()
    try:
        fmpy.simulate_fmu(args.fmu, stop_time=0.01, start_values={"plunger.stroke": -1.0},
                          validate=False, logger=lambda *a: None)
        failed = False
    except Exception as e:
        failed = True
        print(f"     simulate_fmu: {type(e).__name__}: {e}")
    check("fmpy.simulate_fmu with an invalid parameter fails cleanly", failed)

    res = fmpy.simulate_fmu(args.fmu, stop_time=0.05, start_values={"T_oil": args.t_to}, validate=False)
    check("fmpy.simulate_fmu runs the packaged parameters", len(res) > 1 and bool(abs(res["x"][-1]) < 1.0))

    for h, path in args.grid:
        h = float(h)
        rows = read_cli(path)
        s = Slave(md, unzipdir, "grid", logged)
        s.initialize(args.t_from)
        got = []
        for k in range(len(rows) - 1):
            s.set("T_oil", args.t_to)
            s.step(k * h, h)
            got.append(s.get("x", "p_a", "p_b"))
        time = s.get("time")[0] if s.v3 else None
        s.free()
        dx, dpr = deviation(rows, got, stroke, dp)
        exact = dx == 0.0 and dpr == 0.0
        check(f"communication steps of {h * 1e3:.9g} ms ({len(got)} steps) against the CLI on the same grid",
              dx <= TOLERANCE and dpr <= TOLERANCE and (time is None or time == len(got) * h or
                                                        abs(time - len(got) * h) <= 1e-12),
              f"max |dx| {dx:.2e} of the stroke, max |dp| {dpr:.2e} of dp{' (exactly equal)' if exact else ''}")

    if args.reference_csv:
        with open(args.reference_csv, newline="") as f:
            ref = [(float(r["time_s"]), float(r["x_m"])) for r in csv.DictReader(f)]
        times = [r[0] for r in ref]
        sequence = [1e-3, 1e-4, 2.5e-3, 1e-3 / 3.0, 7e-4, 5e-5, 1.7e-3, 1e-2]
        s = Slave(md, unzipdir, "variable", logged)
        s.initialize(args.t_from)
        t, k, worst = 0.0, 0, 0.0
        step = abs(ref[-1][1] - ref[0][1])
        while t + sequence[k % len(sequence)] <= min(0.3, times[-1]):
            h = sequence[k % len(sequence)]
            s.set("T_oil", args.t_to)
            s.step(t, h)
            t += h
            k += 1
            i = min(max(bisect.bisect_left(times, t), 1), len(times) - 1)
            (t0, x0), (t1, x1) = ref[i - 1], ref[i]
            x_ref = x0 + (x1 - x0) * (t - t0) / (t1 - t0)
            worst = max(worst, abs(s.get("x")[0] - x_ref) / step * 100.0)
        s.free()
        check(f"a variable step sequence ({k} steps of {', '.join(f'{h * 1e3:.4g}' for h in sequence)} ms) "
              f"against the reference solver", worst <= 0.5, f"max |dx| {worst:.4f} % of the step")

    if args.platforms:
        names = zipfile.ZipFile(args.fmu).namelist()
        v3 = md.fmiVersion.startswith("3")
        folders = {"x86_64-linux": ("linux64", "so"), "x86_64-windows": ("win64", "dll"),
                   "aarch64-linux": ("aarch64-linux", "so")}
        want = [f"binaries/{p if v3 else folders[p][0]}/compensator.{folders[p][1]}" for p in args.platforms.split(",")]
        missing = [w for w in want if w not in names]
        check(f"the archive carries the binaries of {args.platforms}", not missing, ", ".join(missing))

    failed = checks.count(False)
    print(f"fmu check: {len(checks) - failed} passed, {failed} failed")
    return 1 if failed else 0


def a_start(md, unzipdir, t_oil):
    s = Slave(md, unzipdir, "fresh", [])
    s.initialize(t_oil)
    v = s.get("x", "p_a", "p_b")
    s.free()
    return v


if __name__ == "__main__":
    sys.exit(main())
