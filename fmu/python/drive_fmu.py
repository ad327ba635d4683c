#!/usr/bin/env python3
"""Drives the compensator FMU with an oil-temperature history and plots the
plunger displacement x and the total flow Q0 (docs/fmu.md).

Usage: drive_fmu.py FMU HISTORY.csv [--csv OUT.csv] [--png OUT.png] [--no-plot]

HISTORY.csv has columns time_s,t_c (e.g. data/fmu/oil-temperature.csv).
FMPy's simulate_fmu steps the FMU by its tick (the model description's
default step) and interpolates the temperature between samples; the port
pressures p_supply, p_outlet stay at their start values, the second
sensor's reading NaN (none). The result
(time, T_oil, x, Q0, flags) is written as CSV; with matplotlib installed
(and without --no-plot) also a PNG.
"""

import argparse
import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("history")
    ap.add_argument("--csv", default="compensator-response.csv")
    ap.add_argument("--png", default="compensator-response.png")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()

    history = np.genfromtxt(args.history, delimiter=",", names=True)
    md = read_model_description(args.fmu)
    # The port pressures held at their start values (the file's operating point).
    start = {v.name: float(v.start) for v in md.modelVariables if v.name in ("p_supply", "p_outlet")}
    # No second sensor's reading (NaN): the condition monitor reads nothing.
    signals = np.array(
        [(t, c, start["p_supply"], start["p_outlet"], np.nan) for t, c in zip(history["time_s"], history["t_c"])],
        dtype=[("time", float), ("T_oil", float), ("p_supply", float), ("p_outlet", float), ("second_reading", float)],
    )
    tick = float(md.defaultExperiment.stepSize)
    result = simulate_fmu(
        args.fmu,
        start_time=float(signals["time"][0]),
        stop_time=float(signals["time"][-1]),
        step_size=tick,
        output_interval=10 * tick,
        start_values={"T_oil": float(signals["T_oil"][0])},
        input=signals,
        output=["T_oil", "x", "Q0", "flags"],
    )
    with open(args.csv, "w") as f:
        f.write("time_s,t_oil_c,x_m,q0_m3s,flags\n")
        for row in result:
            f.write(f"{row['time']!r},{row['T_oil']!r},{row['x']!r},{row['Q0']!r},{int(row['flags'])}\n")
    x, q0 = result["x"], result["Q0"]
    print(
        f"{len(result)} rows to {args.csv}: x {x.min() * 1e3:.4f} .. {x.max() * 1e3:.4f} mm, "
        f"Q0 {q0.min() * 6e4:.3f} .. {q0.max() * 6e4:.3f} l/min"
    )
    if not (np.isfinite(x).all() and np.isfinite(q0).all()):
        print("non-finite output", file=sys.stderr)
        return 1
    if args.no_plot:
        return 0
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: the CSV is the result")
        return 0
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7))
    axes[0].plot(result["time"], result["T_oil"])
    axes[0].set_ylabel("T_oil [degC]")
    axes[1].plot(result["time"], x * 1e3)
    axes[1].set_ylabel("x [mm]")
    axes[2].plot(result["time"], q0 * 6e4)
    axes[2].set_ylabel("Q0 [l/min]")
    axes[2].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)
    print(f"plot: {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
