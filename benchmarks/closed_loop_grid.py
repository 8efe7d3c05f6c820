"""Closed-loop Monte Carlo on BIRDy's noise grid (Leboutet et al., Applied Sciences 2021), on a Dask local cluster of 2
workers: ``dynid montecarlo --closed-loop`` (:mod:`dynid.studies.closed_loop_montecarlo`) with its table as Markdown.

The paper's ER-16 (3 joints, its excitation β1, 25 s at 1 kHz) driven by a PID with model feed-forward (5 Hz
bandwidth, velocity filtered at 50 Hz); encoder noise 1e-4, 1e-3, 1e-2 degrees; torque noise 0.05 and 0.1 N·m; every
estimator (OLS, WLS, IRLS, LAD, SDP, ABC, IDIM-IV, DIDIM). ``--band 3`` gives the preprocessing an excitation band of
3 Hz (cutoffs at 30 Hz), which lets the loop's noise into the observation matrix; by default the band is derived from
each log as ``dynid identify`` does.

    .venv/bin/python benchmarks/closed_loop_grid.py [realisations] [--band HZ] [--encoder DEG,..] [--torque NM,..]
        [--robot NAME_OR_DESCRIPTION --joints N]   (e.g. configs/robots/tx40_simulation.toml, 6: the coupled wrist)
        [--estimators ols,idim-iv,didim-sdp] [--excitation EXCITATION_JSON --duration S]
"""

from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def main(argv: list[str]) -> int:
    from dynid.report.study_summaries import closed_loop_study_rows, closed_loop_verdict
    from dynid.studies.closed_loop_montecarlo import (
        ENCODER_NOISE_DEG,
        TORQUE_NOISE,
        ClosedLoopStudyConfig,
        run_closed_loop_study,
    )

    parser = argparse.ArgumentParser()
    parser.add_argument("realisations", type=int, nargs="?", default=10)
    parser.add_argument("--band", type=float, default=None)
    parser.add_argument("--encoder", default=",".join(map(str, ENCODER_NOISE_DEG)))
    parser.add_argument("--torque", default=",".join(map(str, TORQUE_NOISE)))
    parser.add_argument("--robot", default="er16")
    parser.add_argument("--joints", type=int, default=3)
    parser.add_argument("--estimators", default=None, help="comma-separated (default: the study's eight)")
    parser.add_argument("--excitation", default="paper", help="paper (β1), optimized, or an excitation.json of dynid excite")
    parser.add_argument("--duration", type=float, default=25.0, help="seconds of each log")
    args = parser.parse_args(argv)
    chosen = {} if args.estimators is None else {"estimators": tuple(args.estimators.split(","))}
    config = ClosedLoopStudyConfig(**chosen, robot=args.robot, joints=args.joints, encoder_noise=tuple(float(x) for x in args.encoder.split(",")),
                                   torque_noise=tuple(float(x) for x in args.torque.split(",")),
                                   realisations=args.realisations, band=args.band, excitation=args.excitation,
                                   duration=args.duration)
    load = os.getloadavg()[0]
    result = run_closed_loop_study(config, workers=2)
    data = result.to_dict()
    band = "derived from each log" if args.band is None else f"{args.band:g} Hz"
    print(f"{args.robot} ({args.joints} joints), excitation {args.excitation}, {args.duration:g} s, {args.realisations} realisations per "
          f"cell, band {band}, Dask local cluster of 2 workers: "
          f"{result.timings['total']:.0f} s; load {load:.2f} at the start, {os.getloadavg()[0]:.2f} at the end")
    headers, rows, _ = closed_loop_study_rows(data)
    print("| " + " | ".join(headers) + " |")
    print("|" + "---|" * len(headers))
    for row in rows:
        print("| " + " | ".join(row) + " |")
    for line in closed_loop_verdict(data):
        print(line)
    if result.errors:
        print(f"{len(result.errors)} fits failed or did not converge; the first: {result.errors[0]['error']}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
