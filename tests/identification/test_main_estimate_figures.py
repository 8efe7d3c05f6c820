"""The main-estimate finding gives two figures that read differently when they differ: it said "predicts the
validation logs worse (1.11 % against 1.11 % on average)" on a zoo log with a dead channel."""

import numpy as np

from dynid.identification.verdict import _apart


def test_two_different_errors_never_read_the_same(rng):
    for _ in range(200):  # apart by 3e-5 to 30 %: six digits always tell them apart
        worse = float(10 ** rng.uniform(-2, 2))
        better = worse * (1 - 10 ** rng.uniform(-4.5, -0.5))
        a, _, b = _apart(better, worse).partition(" % against ")
        assert a != b.removesuffix(" %") and np.isclose(float(a), better, rtol=1e-2) and np.isclose(float(b[:-2]), worse, rtol=1e-2)
    assert _apart(11.8, 55.4) == "11.8 % against 55.4 %"  # three digits where they suffice (the figures as before)
    assert _apart(1.1104, 1.1141) == "1.110 % against 1.114 %"


def test_the_held_out_figures_of_the_main_estimate_read_apart_too():
    """A log without validation logs: the SDP was the main estimate as it "predicts held-out blocks of the log worse
    (0.208 against 0.208 N·m RMS)" (an ER-16 log of 20 s); the finding now gives the digits that tell every
    candidate's held-out figure apart."""
    import dynid

    robot = dynid.load_robot("er16")
    log = dynid.simulated_log(robot, seconds=20, rng=1)
    result = dynid.Identifier(robot, estimators=["wls", "sdp"]).fit(log.t, log.q, log.tau).result_
    held = result.diagnostics["held_out_rms_error"]
    main = next(f.text for f in result.findings if f.kind == "main")
    assert result.main == "dynid SDP" and held["dynid SDP"] < held["dynid WLS"]
    figures = dict(part.rsplit(" ", 1) for part in main.split("), ")[1].split(": ", 1)[1].split(" N·m RMS")[0].split(", "))
    assert figures["dynid SDP"] != figures["dynid WLS"] and float(figures["dynid SDP"]) < float(figures["dynid WLS"])
