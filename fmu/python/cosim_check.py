#!/usr/bin/env python3
"""The FMI 2.0 FMU simulated by a second importer, libcosim (the
`libcosimpy` wheel, libcosim inside), with the comparison of
`check_fmu.py`: a temperature step at the tick and at every communication
step of `--grid H CSV` gives the trajectory `compensator step --precision
f32` wrote on the same grid, within 1e-6 of the stroke and of dp.

libcosim's clock counts whole nanoseconds: its 1/3 ms is 333,333 ns, so
that grid's CLI run is at 333,333 ns too (the FMU takes any step exactly).
A grid that is not whole nanoseconds is left to FMPy.

Usage: cosim_check.py FMU --step-csv F --from C --to C [--grid H CSV]...
Ends with `cosim check: N passed, M failed`; exit status 1 if any failed.
"""

import argparse
import sys

from check_fmu import check, checks, deviation, read_cli
from fmpy import read_model_description
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

TOLERANCE = 1e-6


def run(fmu, vr, step_ns, t_from, t_to, n):
    """The FMU at rest at t_from, the oil at t_to from the first step; the
    outputs after each of n steps of step_ns."""
    ex = CosimExecution.from_step_size(step_size=step_ns)
    slave = CosimLocalSlave(fmu_path=fmu, instance_name="compensator")
    i = ex.add_local_slave(local_slave=slave)
    ex.real_initial_value(i, vr["T_oil"], t_from)
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    override = CosimManipulator.create_override()
    ex.add_manipulator(override)
    # Applied before the first step, after initialisation at t_from.
    override.slave_real_values(i, [vr["T_oil"]], [t_to])
    out = []
    for _ in range(n):
        if not ex.step():
            return out, ex.status().current_time
        out.append(observer.last_real_values(i, [vr["x"], vr["p_a"], vr["p_b"]]))
    return out, ex.status().current_time


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("--step-csv", required=True)
    ap.add_argument("--from", dest="t_from", type=float, required=True)
    ap.add_argument("--to", dest="t_to", type=float, required=True)
    ap.add_argument("--grid", nargs=2, action="append", default=[], metavar=("H", "CSV"))
    args = ap.parse_args()
    log_output_level(CosimLogLevel.WARNING)
    md = read_model_description(args.fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    stroke = next(float(v.start) for v in md.modelVariables if v.name == "plunger.stroke")
    dp = next(float(v.start) for v in md.modelVariables if v.name == "operating.pressure_drop")
    tick = float(md.defaultExperiment.stepSize)
    runs = [(tick, args.step_csv)] + [(float(h), path) for h, path in args.grid]
    for h, path in runs:
        ns = round(h * 1e9)
        if abs(ns * 1e-9 - h) > 1e-15:
            print(f"     {h * 1e3:.9g} ms is not whole nanoseconds: left to FMPy")
            continue
        rows = read_cli(path)
        n = len(rows) - 1
        got, end = run(args.fmu, vr, ns, args.t_from, args.t_to, n)
        if len(got) < n:
            check(f"libcosim, steps of {ns} ns", False, f"stopped after {len(got)} of {n} steps at {end} ns")
            continue
        dx, dpr = deviation(rows, got, stroke, dp)
        exact = dx == 0.0 and dpr == 0.0
        check(f"libcosim, {n} steps of {ns} ns ({args.t_from} -> {args.t_to} C), against compensator step "
              "on the same grid", dx <= TOLERANCE and dpr <= TOLERANCE and end == n * ns,
              f"max |dx| {dx:.2e} of the stroke, max |dp| {dpr:.2e} of dp{' (exactly equal)' if exact else ''}")
    failed = checks.count(False)
    print(f"cosim check: {len(checks) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
