"""Digests of what every config in ``configs/``, ``dynid run`` and a Monte Carlo realisation produce.

A digest is the flattened ``results.json`` (every leaf under its JSON path: numbers, strings, booleans), without
wall times and file paths. ``tests/test_digests.py`` compares each case against ``tests/data/digests.json``, so a
restructuring that is meant to change nothing is shown to change nothing.

Regenerate (only when a change of results is intended, and say so in the commit)::

    .venv/bin/python -m tests.digests [case ...]
"""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STORE = ROOT / "tests" / "data" / "digests.json"

IDENTIFY = ("ur10e", "tx40", "tx40-full", "kuka_kr300", "kuka_med7")
EXCITE = ("excite-er16", "excite-ur10e", "excite-er16-6dof", "excite-er16-beta1-envelope", "excite-tx40")
CASES = (*(f"identify:{c}" for c in IDENTIFY), *(f"excite:{c}" for c in EXCITE), "run", "montecarlo")

SKIPPED = {"seconds", "timings", "config", "path", "file", "cluster"}
"""Keys whose values are wall times or file paths: not results."""

RTOL = 1e-6
ATOL = 1e-12
SOLVER_RTOL = 1e-4
"""Numbers agree when ``|a - b| <= RTOL·max(|a|, |b|) + ATOL``. Not to the last digit: NumPy's and SciPy's OpenBLAS
picks its kernels by the CPU (DYNAMIC_ARCH), and another CPU moves the last digits (measured: 1e-9 to 1e-8 relative
on ``dynid run``'s bootstrap bounds between an Intel and an AMD machine), while a changed result moves far more.
Estimates of the SDP and consistency margins are solver optima (cvxpy and Clarabel's tolerances): :data:`SOLVER_RTOL`,
as for the whole Monte Carlo case, whose estimate arrays hold the SDP's rows."""

SOLVER_PATHS = ("consistency_margin", "SDP", "sdp", "pseudo_inertia")

EIGENVALUE_ATOL = 1e-6
"""The smallest eigenvalue of a link's pseudo-inertia in an SDP estimate [kg·m²]: 0 up to the solver's tolerance where the
link's constraint is active (measured: 5.6793e-07 against 5.6803e-07 on the UR10e between two machines), so compared
to this absolute tolerance, not relative to itself; a link that turns inconsistent moves it by far more."""

UNDEFINED = "correlation"
"""A comparison's correlation of a joint whose torque does not vary beyond its noise (``correlation_meaningful``
false in results.json) is noise against noise: the last digits of a rest detection change it (measured: -0.0070
against -0.0112 on the UR10e's resting log p2 between two machines), and it is not compared."""

OPTIMISED = ("/design/", "/trajectory/", "/set_points/", "/cell_clearance", "/self_clearance/")
"""An excitation design is a local optimum of a non-convex problem, reached from several starts (the UR10e's initial
trajectory is itself searched for): on another CPU the last digits of one step send a start to another optimum
(measured: cond 20.73 against 21.33 for excite-er16, the UR10e's initial cond 1246.4 against 1247.4; excite-ur10e's
design cond 85.00 where the digests were made, 90.96 on an AVX-512 machine on 2026-11-27, 7.0 % apart, with the same
code; the set-points and clearances of such another optimum: excite-er16-6dof's closest approach to the cell 0.0295
against 0.0625 m between an Intel's AVX-512 kernels and an AMD's Haswell ones on 2026-12-02). Its leaves are compared
on the criterion alone (:data:`DESIGN_CHECKED`, within :data:`DESIGN_RTOL`: another
optimum, not another quality of design); limits, settings and names as every other value."""
DESIGN_CHECKED = ("/design/cond", "/design/initial_cond", "/design/feasible")
DESIGN_RTOL = 0.15

SCALED = ("/estimates/", "/diagnostics/file_terms/")
"""An SDP estimate's values (:data:`SOLVER_PATHS` under this prefix) are compared to :data:`SOLVER_RTOL` of the
largest magnitude among the estimate's values besides their own: an optimum holds its values to the solver's
tolerance on the problem's scale, not each to itself. A friction at its bound of 0 (the LBR Med7's SDP: fv1 = 2.0e-9 on
one CPU, 3.7e-10 on another) or a weakly determined inertia (its XX1, 0.07189 against 0.07186) moves by more than its
own 1e-4 (measured between a Zen 3, AVX2 kernels, where the digests were made, and a Zen 4, AVX-512 kernels). The
friction pair folded from an SDP estimate (``diagnostics.file_terms``) alike: the Med7's fv2 at its bound, 5.1e-8
where the digests were made, 3.3e-7 on an AMD EPYC's Haswell kernels (2026-12-02)."""

STATISTICS = "/diagnostics/"
STATISTICS_RTOL = 1e-4
"""The diagnostics are statistics of the fit's residuals (autocorrelations, t-values, the moving-block bootstrap's
refits): on the KR 300 (cond 2.9e8) those two CPUs' kernels move them by up to 6e-5 relative."""

MARGINS = ("consistency_margin",)
"""A consistency margin is the smallest eigenvalue of the links' pseudo-inertias: compared as one
(:data:`EIGENVALUE_ATOL`; the Med7's SDP: -1.55e-8 against -2.81e-8 on those two CPUs)."""

CROSS_VALIDATION = ("/settings/friction_models/out_of_fold_rms_error",)
CROSS_VALIDATION_RTOL = 0.1
"""The friction models' out-of-fold errors of the candidates: fits on four fifths of the log, whose rank decisions on
an ill-conditioned log follow the CPU's last digits (the KR 300: a candidate the choice rejects moved by 9 % between
those CPUs). The choice itself (every joint's model) and every estimate made with it are compared as any value."""


def data_root(config: Path) -> Path | None:
    """The shared data folder of an identification config (None when the workplace's data are absent)."""
    import tomllib

    doc = tomllib.loads(config.read_text())
    name = Path(doc.get("data_root", ".")).name
    import os

    for root in (os.environ.get("DYNID_SHARED_DATA"), ROOT.parent / "shared" / "data", Path("/work/shared/data")):
        if root and (Path(root) / name).is_dir():
            return Path(root) / name
    return None


def compute(case: str) -> dict:
    """``results.json`` of ``case`` as a plain dict (what the CLI writes)."""
    from dynid.io.files import _clean

    kind, _, name = case.partition(":")
    if kind == "identify":
        from dynid import load_identification_config, run_identification

        path = ROOT / "configs" / f"{name}.toml"
        root = data_root(path)
        if root is None:
            raise FileNotFoundError(f"data of {path.name} not found")
        return of_result(run_identification(load_identification_config(path, data_root=root)))
    if kind == "excite":
        from dynid.identification.excite import run_excitation
        from dynid.io.config.excitation_config import load_excitation_config

        return _clean(run_excitation(load_excitation_config(ROOT / "configs" / f"{name}.toml")).to_dict())
    if kind == "run":
        from dynid import PaperExperimentConfig, run_paper_experiment

        return _clean(run_paper_experiment(PaperExperimentConfig()).to_dict())
    if kind == "montecarlo":
        from dynid.studies.montecarlo import MonteCarloConfig, _prepare, simulate_realisation

        config = MonteCarloConfig(noise_levels=(0.05, 0.2), realisations=2, estimators=("ols", "wls", "irls", "lad", "sdp", "abc"),
                                  duration=8.0, rate=100.0, maxiter=5)
        setup = _prepare(config)
        out = {}
        for level in range(2):
            for r in range(2):
                one = simulate_realisation(setup, level, r)
                out[f"{level}/{r}"] = {"params": one["params"], "errors": one["errors"]}
        return _clean(out)
    raise ValueError(f"unknown case {case!r}")


def of_result(result) -> dict:
    """``results.json`` of an identification result as a plain dict (what the CLI writes)."""
    from dynid.io.files import _clean

    return _clean(result.to_dict())


def _portable(text: str) -> str:
    """A path in a result with the shared data folder written ``<data>`` and the checkout ``<repo>``, so that a
    digest stored on one machine compares on another one (CI checks out elsewhere)."""
    roots = [os.environ.get("DYNID_SHARED_DATA"), str(ROOT.parent / "shared" / "data"), "/work/shared/data"]
    for root in filter(None, roots):
        text = text.replace(str(Path(root).resolve()), "<data>").replace(root, "<data>")
    return text.replace(str(ROOT), "<repo>")


def flatten(obj, prefix: str = "") -> dict:
    """JSON path -> leaf (number, string, bool or None), without :data:`SKIPPED` keys; paths made portable."""
    out = {}
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k not in SKIPPED:
                out.update(flatten(v, f"{prefix}/{k}"))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            out.update(flatten(v, f"{prefix}[{i}]"))
    else:
        out[prefix] = _portable(obj) if isinstance(obj, str) else obj
    return out


def differences(stored: dict, now: dict, renamed: dict | None = None, dropped: tuple = (), solver: bool = False) -> list[str]:
    """What differs between a stored digest and today's (every stored path must hold the same value; new paths are
    allowed). ``renamed``: stored path prefix -> today's prefix; ``dropped``: stored paths no longer written;
    ``solver``: every number a solver's optimum (:data:`SOLVER_RTOL`)."""
    renamed = renamed or {}
    out = []
    scales = _sibling_scales(stored)
    for path, old in stored.items():
        if path in dropped or _undefined(path, stored) or _undefined(path, now):
            continue
        new_path = path
        for a, b in renamed.items():  # a prefix ending in "/" renames a subtree, any other one path or its children
            if path == a or path.startswith(a if a.endswith("/") else a + "/") or (not a.endswith("/") and path.startswith(a + "[")):
                new_path = b + path[len(a):]
                break
        if new_path not in now:
            out.append(f"{path}: missing")
            continue
        new = now[new_path]
        optimised = path.startswith(OPTIMISED)
        if optimised and path not in DESIGN_CHECKED:
            continue
        if isinstance(old, float) or isinstance(new, float):
            if old is None or new is None or isinstance(old, (str, bool)) or isinstance(new, (str, bool)):
                same = old == new
            else:
                same = math.isclose(old, new, rel_tol=_rtol(path, optimised, solver), abs_tol=_atol(path, scales))
        else:
            same = old == new
        if not same:
            out.append(f"{path}: {old!r} -> {new!r}")
    return out


def _rtol(path: str, optimised: bool, solver: bool) -> float:
    """The relative tolerance of one stored leaf (module constants)."""
    if optimised:
        return DESIGN_RTOL
    if path.startswith(CROSS_VALIDATION):
        return CROSS_VALIDATION_RTOL
    if path.startswith(STATISTICS):
        return STATISTICS_RTOL
    return SOLVER_RTOL if solver or any(p in path for p in SOLVER_PATHS) else RTOL


def _atol(path: str, scales: dict) -> float:
    """The absolute tolerance of one stored leaf: :data:`EIGENVALUE_ATOL` for eigenvalues and margins, a share of its
    siblings' magnitude for an SDP estimate's values (:data:`SCALED`), else :data:`ATOL`."""
    if "pseudo_inertia_min_eig" in path or any(m in path for m in MARGINS):
        return EIGENVALUE_ATOL
    if path.startswith(SCALED) and any(p in path for p in SOLVER_PATHS):
        return max(ATOL, SOLVER_RTOL * scales.get(_parent(path), 0.0))
    return ATOL


def _parent(path: str) -> str:
    """A leaf's parent: the path without its last key or index."""
    return path[: path.rindex("[")] if path.endswith("]") else path.rsplit("/", 1)[0]


def _sibling_scales(digest: dict) -> dict:
    """Parent path -> largest magnitude of the numbers under it."""
    out: dict = {}
    for path, value in digest.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
            key = _parent(path)
            out[key] = max(out.get(key, 0.0), abs(float(value)))
    return out


def _undefined(path: str, digest: dict) -> bool:
    """Whether ``path`` is a correlation the digest's own comparison flags as meaningless (:data:`UNDEFINED`)."""
    head, sep, tail = path.partition("/metrics/")
    if not sep or f"/{UNDEFINED}[" not in tail:
        return False
    joint = tail.rsplit("[", 1)[1].rstrip("]")
    return digest.get(f"{head}/{UNDEFINED}_meaningful[{joint}]") is False


def load() -> dict:
    return json.loads(STORE.read_text()) if STORE.exists() else {}


def main(argv: list[str]) -> int:
    from threadpoolctl import threadpool_limits

    store = load()
    cases = argv or list(CASES)
    with threadpool_limits(1):
        for case in cases:
            try:
                store[case] = flatten(compute(case))
            except FileNotFoundError as exc:
                print(f"{case}: skipped ({exc})")
                continue
            print(f"{case}: {len(store[case])} leaves")
    STORE.parent.mkdir(parents=True, exist_ok=True)
    STORE.write_text(json.dumps(store, indent=None, separators=(',', ':'), sort_keys=True, ensure_ascii=False, allow_nan=False) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
