#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""viscera-lab from Python: analyze a data set, print what the baseline gets wrong and what the
extended model gains on held-out tests, and plot each test with both models.

    PYTHONPATH=build/python python3 examples/python/lab_fit.py data/titin-passive-muscle --plot titin.png
"""

from __future__ import annotations

import argparse
import sys
import time

import viscera


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dataset", help="a data set folder (dataset.json and one CSV per test)")
    p.add_argument("--plot", metavar="PNG", help="write the tests with both models to this file")
    p.add_argument("--quick", action="store_true", help="no specimen runs and no bootstrap (a first look)")
    a = p.parse_args()
    t0 = time.monotonic()
    try:
        d = viscera.lab.read_dataset(a.dataset)
    except viscera.InputError as e:
        print(f"lab_fit.py: {e}", file=sys.stderr)
        return 2
    print(f"{d.name}: {len(d.tests)} tests, {d.mode}")
    result = viscera.lab.analyze(d, specimen=not a.quick, bootstrap_replicates=0 if a.quick else 40,
                                 progress=lambda line: print(f"[{time.monotonic() - t0:6.1f} s] {line}", file=sys.stderr))
    r = result.report
    print(result.verdict)
    print(f"causes ({r['causes_status']}): {', '.join(result.causes) or 'none'}")
    print(f"held-out RMS: baseline {r['baseline']['heldout_rms_pa']:.4g} Pa, final {r['final']['heldout_rms_pa']:.4g} Pa, gain {r['gain']:.3g}x")
    nested = r.get("nested_leave_one_out", {})
    if nested.get("ran"):
        print(f"honest gain (nested leave-one-out): {nested['gain']:.3g}x")
    for par in r["parameters"]["parameters"]:
        print(f"  {par['name']} = {par['value']:.4g} {par['unit']}")
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        tests = result.dataset.tests
        fig, axes = plt.subplots(len(tests), 1, figsize=(8, 3 * len(tests)))
        for t, ax in zip(tests, axes if len(tests) > 1 else [axes]):
            result.plot(t.file, ax)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=100)
        print(f"wrote {a.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
