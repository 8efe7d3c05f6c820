"""One joint's torque channel read with the wrong sign, on the real logs: which check names it.

Each of the four real configs (``configs/``) is identified as configured, then once per joint with that joint's torque
(or current) negated in every log of the config (a channel's sign convention holds for the identification and the
validation logs alike). Per case it prints the sign findings: the description's nominal model's
(:func:`dynid.validation.diagnostics.sign_findings`, where it predicts the joint's torque) and the physically
consistent refit's (:mod:`dynid.identification.flipped_joints`, where it does not); and the main estimate's mean
validation error on the one yardstick against the log read right, so that a joint left unnamed is seen to matter or
not. From the repository root, with the shared data beside it: ``.venv/bin/python benchmarks/flipped_torques.py``
(a few minutes).
"""

from __future__ import annotations

import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CONFIGS = ("ur10e", "tx40", "kuka_kr300", "kuka_med7")


def _negated(spec, j: int):
    """A dataset spec with joint ``j``'s torque (or current) channel negated."""
    kind = "torques" if "torques" in spec.signals else "currents"
    signal = spec.signals[kind]
    n = len(signal.columns)
    scale = np.broadcast_to(np.asarray(signal.scale, dtype=float), (n,)).copy()
    scale[j] *= -1.0
    return replace(spec, signals={**spec.signals, kind: replace(signal, scale=tuple(scale))})


def _case(config, label: str, right: float | None) -> float:
    from dynid.identification.run import run_identification

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = run_identification(config)
    yard = result.diagnostics["yardstick"]["mean_global_relative_error"][result.main]
    signs = [f.text.split(": the ")[0] + (" (refit)" if "physically consistent estimate cannot" in f.text else
                                          " (nominal)") for f in result.findings if f.kind == "sign"]
    other = sorted({f.kind for f in result.findings if f.kind in ("angles", "gravity", "scale", "order", "misread")})
    versus = "" if right is None else f" | {yard / right:.2f}"
    print(f"{label} | {'; '.join(signs) or 'none'} | {', '.join(other) or '-'} | {result.main} {yard:.2f}{versus}",
          flush=True)
    return yard


def main() -> int:
    from dynid.io.config.identification_config import load_identification_config

    print("case | sign findings (which check) | other reading findings | main estimate, mean validation error % on "
          "the one yardstick | against the log read right")
    for name in CONFIGS:
        config = load_identification_config(REPO / "configs" / f"{name}.toml")
        right = _case(config, f"{name} as configured", None)
        for j in range(config.robot.n_dof):
            flipped = replace(config, identification=_negated(config.identification, j),
                              validation=tuple(_negated(v, j) for v in config.validation))
            _case(flipped, f"{name} J{j + 1} negated", right)
    return 0


if __name__ == "__main__":
    sys.exit(main())
