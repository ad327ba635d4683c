#!/usr/bin/env python3
"""The FMU in a hydraulic circuit, co-simulated with a small Python loop
(FMPy's FMI 2.0 slave), against the reference solution of the coupled
circuit (docs/fmu.md, "In a circuit").

The circuit: a pressure source (the supply history) -> the compensator
(the FMU: inputs p_supply, p_outlet, T_oil; output Q0) -> a line of
capacitance C (its pressure p is the FMU's p_outlet) -> a load orifice to a
tank, Q_load = K sqrt(p - p_tank). Each communication step of h: the FMU
steps with the supply at the step's midpoint and the line's pressure from
the step before (held); then the line is integrated over the step with the
FMU's new Q0, implicitly (backward Euler, a closed-form root):

    C (p' - p) / h = Q0 - K sqrt(p' - p_tank)

The reference (`cargo run -p compensator-fmu --example circuit_reference`)
solves the compensator and the line as one stiff system (Radau5); the
coupling here is first order in h, so its error falls with the step.

Usage: circuit.py FMU REFERENCE_DIR [--steps 1e-3 1e-4] [--csv OUT.csv]
Prints, per step size, the largest |Q0 - Q0_ref| in % of the reference's
largest Q0 (and of p_outlet in % of its largest); ends with
`circuit: N passed, M failed` (goal: within 1 % at the finest step, and
the error smaller at the finer step).
"""

import argparse
import csv
import json
import math
import sys

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

GOAL_PCT = 1.0


def supply_at(points, t):
    """The supply history [Pa] at t: piecewise linear, a jump where two
    points share a time (the later value from there on)."""
    value = points[0][1]
    for (ta, va), (tb, vb) in zip(points, points[1:]):
        if ta <= t < tb:
            return va + (vb - va) * (t - ta) / (tb - ta)
        if t >= tb:
            value = vb
    return value


def run(md, unzipdir, circuit, outlet0, h):
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="circuit")
    s.instantiate()
    supply = circuit["supply"]
    c, k, tank = circuit["capacitance_m3_per_pa"], circuit["load_coefficient"], circuit["tank_pa"]
    p = outlet0
    s.setReal([vr["T_oil"], vr["p_supply"], vr["p_outlet"]], [circuit["from_c"], supply_at(supply, 0.0), p])
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    n = round(circuit["t_end_s"] / h)
    rows = []
    for i in range(n):
        t = i * h
        s.setReal([vr["T_oil"], vr["p_supply"], vr["p_outlet"]],
                  [circuit["to_c"], supply_at(supply, t + 0.5 * h), p])
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        q0 = s.getReal([vr["Q0"]])[0]
        a = c / h
        rhs = q0 + a * (p - tank)
        root = (-k + math.sqrt(k * k + 4.0 * a * max(rhs, 0.0))) / (2.0 * a)
        p = tank + root * root
        rows.append(((i + 1) * h, q0, p))
    s.terminate()
    s.freeInstance()
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("reference_dir")
    ap.add_argument("--steps", type=float, nargs="+", default=[1e-3, 1e-4])
    ap.add_argument("--csv", help="the finest step's result: time_s,q0_m3s,p_outlet_pa,q0_ref_m3s")
    args = ap.parse_args()
    with open(f"{args.reference_dir}/circuit.json") as f:
        circuit = json.load(f)
    with open(f"{args.reference_dir}/reference.csv", newline="") as f:
        ref = [(float(r["time_s"]), float(r["q0_m3s"]), float(r["p_outlet_pa"])) for r in csv.DictReader(f)]
    dt_ref = ref[1][0] - ref[0][0]
    q_max = max(r[1] for r in ref)
    p_max = max(r[2] for r in ref)
    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    errors = []
    finest = None
    for h in args.steps:
        rows = run(md, unzipdir, circuit, ref[0][2], h)
        dq = dp = 0.0
        for t, q0, p in rows:
            r = ref[round(t / dt_ref)]
            dq = max(dq, abs(q0 - r[1]) / q_max * 100.0)
            dp = max(dp, abs(p - r[2]) / p_max * 100.0)
        errors.append(dq)
        print(f"step {h:g} s: {len(rows)} steps, max |Q0 - Q0_ref| {dq:.3f} % of {q_max * 6e4:.3f} l/min, "
              f"max |p_outlet - ref| {dp:.3f} % of {p_max / 1e5:.3f} bar", flush=True)
        finest = (h, rows)
    checks = [errors[-1] <= GOAL_PCT, len(errors) < 2 or errors[-1] < errors[0]]
    print(f"{'ok  ' if checks[0] else 'FAIL'} the finest step's Q0 within {GOAL_PCT} % of the reference")
    if len(errors) > 1:
        print(f"{'ok  ' if checks[1] else 'FAIL'} the error falls with the step "
              f"({errors[0]:.3f} % -> {errors[-1]:.3f} %)")
    if args.csv and finest:
        with open(args.csv, "w") as f:
            f.write("time_s,q0_m3s,p_outlet_pa,q0_ref_m3s\n")
            for t, q0, p in finest[1]:
                f.write(f"{t!r},{q0!r},{p!r},{ref[round(t / dt_ref)][1]!r}\n")
    failed = checks.count(False)
    print(f"circuit: {len(checks) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
