"""identify's first line judges what dynid export writes: on the zoo's UR5 short log it said "model ready: dynid SDP"
while the publish gate had judged the main estimate (WLS) and export then warned that the SDP predicts J2 worse than
the description's nominal model."""

from types import SimpleNamespace

import numpy as np

from dynid.report.summaries import readiness
from dynid.validation.diagnostics import nominal_gate
from dynid.validation.torques import TorqueComparison


def _result(rng, sdp_error_on_j2: float):
    t = np.arange(500) * 0.01
    measured = np.column_stack([np.sin(t), 2 * np.cos(0.7 * t), np.sin(0.3 * t + 1)])
    close = measured + 0.01 * rng.standard_normal(measured.shape)
    nominal = 1.1 * measured
    sdp = close.copy()
    sdp[:, 1] = measured[:, 1] * (1 + sdp_error_on_j2)
    v = TorqueComparison("validation", t, measured, {"dynid WLS": close, "dynid SDP": sdp, "nominal": nominal})
    _, stats = nominal_gate([v], "dynid WLS", "nominal")  # the gate as identify runs it: on the main estimate
    return SimpleNamespace(findings=(), estimators=("wls", "sdp"), validations=(v,),
                           estimates={"dynid WLS": SimpleNamespace(standard=None),
                                      "dynid SDP": SimpleNamespace(standard=np.ones(3))},
                           consistency_verdicts={"dynid WLS": "no: …", "dynid SDP": "yes"},
                           diagnostics={"nominal_set": "nominal", "versus_nominal": stats})


def test_the_first_line_judges_the_estimate_export_writes(rng):
    worse = _result(rng, 0.2)  # the SDP misses J2 by 20 %, the nominal model by 10 %; WLS is better everywhere
    assert worse.diagnostics["versus_nominal"]["validation"]["worse_joints"] == []
    line = readiness(worse)
    assert line.text.startswith("not ready: the description's nominal model predicts J2 of validation better than "
                                "dynid SDP (what dynid export writes)"), line.text
    assert readiness(_result(rng, 0.02)).text.startswith("model ready: dynid SDP")
