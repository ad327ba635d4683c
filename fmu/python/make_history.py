#!/usr/bin/env python3
"""Writes data/fmu/oil-temperature.csv: a synthetic oil-temperature history
shaped like a bench log (a warm-up, a hold, a cold-oil injection, a slow
recovery), sampled at 50 Hz (the MAX31865's conversion rate at 50 Hz mains)
and quantised to its resolution with seeded noise. Not a measurement: the
example input of docs/fmu.md, reproducible with this script.

Usage: make_history.py [OUT]   (default data/fmu/oil-temperature.csv)
"""

import math
import random
import sys

RATE_HZ = 50.0
DURATION_S = 20.0
# One code of the MAX31865 with a PT100 and 430 ohm reference: 430 / 32768
# ohm, about 0.034 C near 40 C.
QUANTUM_C = 430.0 / 32768.0 / 0.385


def temperature(t):
    if t < 2.0:
        return 32.0
    if t < 10.0:  # warm-up towards 68 C, time constant 2.5 s
        return 68.0 - 36.0 * math.exp(-(t - 2.0) / 2.5)
    if t < 13.0:
        return 68.0 - 36.0 * math.exp(-8.0 / 2.5)
    # cold oil injected: 20 C down within 0.2 s, then recovery (4 s)
    base = 68.0 - 36.0 * math.exp(-8.0 / 2.5)
    drop = 20.0 * min(1.0, (t - 13.0) / 0.2)
    return base - drop * math.exp(-max(0.0, t - 13.2) / 4.0)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "data/fmu/oil-temperature.csv"
    rng = random.Random(20261201)
    n = int(DURATION_S * RATE_HZ)
    with open(out, "w") as f:
        f.write("time_s,t_c\n")
        for k in range(n + 1):
            t = k / RATE_HZ
            value = temperature(t) + rng.gauss(0.0, 0.02)
            f.write(f"{t:.2f},{round(value / QUANTUM_C) * QUANTUM_C:.4f}\n")


if __name__ == "__main__":
    main()
