"""Evidence for the main-estimate choice that does not read the validation logs' torques (issue "Never worse than
the description", item 1): measured on the real logs and their short windows.

For each case (a config of ``configs/`` as it is, or cut to a short window as ``short_windows.py`` cuts them) this
identifies with the defaults (the candidates' validation figures on the one yardstick: the truth the rules are judged
by), then refits each candidate — least squares (WLS), the physically consistent SDP, the description's rigid body with
the drive terms fitted (drive-only) — on every ``K - 1`` of ``K`` contiguous blocks of the identification log, and
stores, per validation log, every full and block-refitted set's predicted torques on the validation log's states.
What a torque-free rule may use from that: the identification log's held-out block errors, and the spread and
disagreement of the predictions on the validation logs' states; the measured validation torques only score.

``--collect`` writes ``/tmp/torque_free/<case>.npz`` (about 10 minutes for the 22 cases); without it, the rules are
evaluated on what was collected and one table printed. From the repository root: ``.venv/bin/python
benchmarks/torque_free.py --collect``.
"""

from __future__ import annotations

import json
import sys
import tempfile
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

FOLDS = 5
OUT = Path("/tmp/torque_free")


def _cases() -> list[tuple[str, str, object]]:
    from short_windows import OTHER_WINDOWS, WINDOWS

    return ([("ur10e", "full", None), ("kuka_kr300", "full", None), ("kuka_med7", "full", None), ("tx40", "full", None)]
            + [("ur10e", f"{a}-{b}", (a, b)) for a, b in WINDOWS]
            + [(n, f"{a:g}-{b:g}", (a, b)) for n, ws in OTHER_WINDOWS.items() for a, b in ws])


def _config_path(name: str, window, folder: Path) -> tuple[Path, Path]:
    from real_logs import DATA, GRIDS
    from real_logs import _config as full_config
    from short_windows import _window_config

    if window is not None:
        return _window_config(name, window, folder)
    return full_config(name, folder, None, None), DATA / GRIDS[name][0]


def _fold_variants(robot, base, recording, data, given, one_way) -> tuple:
    """:func:`dynid.identification.drive_only.preprocessing_variants`, each variant's rows split into the folds."""
    from dynid.estimators.accumulate import LeastSquaresAccumulator
    from dynid.identification.drive_only import CUTOFF_FACTORS, prepared_variant, variants_judge
    from dynid.preprocessing.preparation import base_chunks

    if not variants_judge(robot, data, one_way):
        return ()
    out = []
    for f in CUTOFF_FACTORS:
        variant = prepared_variant(recording, data, given, f)
        accs = [LeastSquaresAccumulator(base.n_base, robot.n_dof) for _ in range(FOLDS)]
        for index, y, tau, keep in base_chunks(robot, base, variant):
            fold = index * FOLDS // variant.t.shape[0]
            for k in np.unique(fold):
                sel = fold == k
                accs[k].add(y[sel].reshape(-1, base.n_base), tau[sel].reshape(-1), keep[sel].reshape(-1))
        out.append((f, accs))
    return tuple(out)


def collect(name: str, tag: str, window, folder: Path) -> None:
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.dynamics.layout import consistency_layout
    from dynid.estimators.accumulate import LeastSquaresAccumulator
    from dynid.estimators.physically_consistent import PhysicallyConsistentLeastSquares
    from dynid.estimators.problem import FitData
    from dynid.identification.drive_only import drive_only
    from dynid.identification.estimates import DRIVE_ONLY_LABEL, SDP_LABEL
    from dynid.identification.estimation_pass import one_way_joints
    from dynid.identification.evidence import yardstick_reference, yardstick_scores
    from dynid.identification.run import pipeline_of, run_identification
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from dynid.preprocessing.preparation import base_chunks

    path, root = _config_path(name, window, folder)
    config = load_identification_config(path, data_root=root)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = run_identification(config)
    yard = result.diagnostics["yardstick"]["mean_global_relative_error"]
    nominal = result.diagnostics["nominal_set"]
    labels = {"ls": result.label, "sdp": SDP_LABEL, "drive": DRIVE_ONLY_LABEL, "nominal": nominal}
    recording = load_recording(config.identification, config.robot)
    checked = tuple(load_recording(s, config.robot) for s in config.validation)
    base0 = base_parameters(config.robot, rng=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        prepared = pipeline_of(config).prepare(recording, base0)
    robot, base, data = prepared.robot, prepared.base, prepared.data
    n, p, n_s = robot.n_dof, robot.n_params, data.t.shape[0]
    std_f = [LeastSquaresAccumulator(p, n) for _ in range(FOLDS)]
    base_f = [LeastSquaresAccumulator(base.n_base, n) for _ in range(FOLDS)]
    for index, y, tau, keep in base_chunks(robot, base, data, standard=True):
        yb = base.base_observation(y)
        fold = index * FOLDS // n_s
        for k in np.unique(fold):
            s = fold == k
            std_f[k].add(y[s].reshape(-1, p), tau[s].reshape(-1), keep[s].reshape(-1))
            base_f[k].add(yb[s].reshape(-1, base.n_base), tau[s].reshape(-1), keep[s].reshape(-1))
    weights = 1.0 / np.where(result.joint_std > 0, result.joint_std, 1.0)
    one_way = one_way_joints(data)
    variants = () if "--no-fold-variants" in sys.argv else _fold_variants(robot, base, recording, data, config.preprocessing, one_way)
    beta_nom = base.base_from_standard(robot.standard_parameters())
    links, nonneg = consistency_layout(robot)
    full = {"ls": result.estimates[result.label].params, "sdp": result.estimates[SDP_LABEL].params,
            "drive": result.drive_only.params, "nominal": beta_nom}
    sets = {f"{c}": b for c, b in full.items()}
    held = {c: np.zeros(n) for c in full}
    rows = 0
    for k in range(FOLDS):
        rest_b = LeastSquaresAccumulator.merged([a for i, a in enumerate(base_f) if i != k])
        rest_s = LeastSquaresAccumulator.merged([a for i, a in enumerate(std_f) if i != k])
        sol = rest_b.solve(joint_weights=weights, prior=beta_nom)
        reduced = rest_s.reduced(weights)
        est = PhysicallyConsistentLeastSquares()
        est.fit(reduced[:, :p], reduced[:, p], problem=FitData(layout=(links, nonneg), prior=robot.standard_parameters()))
        fitted = drive_only(robot, base, rest_b, joint_weights=weights, one_way=one_way,
                            variants=tuple((f, LeastSquaresAccumulator.merged([a for i, a in enumerate(accs) if i != k]))
                                           for f, accs in variants))
        refit = {"ls": sol.params, "sdp": base.base_from_standard(est.params_),
                 "drive": full["drive"] if fitted is None else fitted.params, "nominal": beta_nom}
        for c, b in refit.items():
            sets[f"{c}#{k}"] = b
            held[c] += base_f[k].joint_residual_sumsq(b)
        rows += int(base_f[k].rows.sum())
    scored = yardstick_scores(replace(config, robot=robot), base, sets, checked, resolved=data.settings,
                              reference=yardstick_reference(recording))
    out = {"labels": json.dumps(labels), "truth": json.dumps({c: yard[labels[c]] for c in labels}),
           "main": result.main, "fit_std": np.asarray(result.joint_std, dtype=float),
           "fit_rms": np.array([result.fit.metrics()[labels[c]]["global_relative_error"] if labels[c] in result.fit.predicted
                                else np.nan for c in labels]),
           "held": np.array([np.sqrt(held[c].sum() / max(rows, 1)) for c in ("ls", "sdp", "drive", "nominal")]),
           "tau_rms_fit": np.sqrt(np.mean(np.asarray(data.tau, dtype=float) ** 2))}
    for v, comp in enumerate(scored):
        out[f"v{v}_measured"] = comp.measured
        out[f"v{v}_resting"] = np.zeros(comp.measured.shape, dtype=bool) if comp.resting is None else comp.resting
        out[f"v{v}_err"] = np.array([comp.metrics()[c]["global_relative_error"] for c in full])
        for label, pred in comp.predicted.items():  # at rest, the prediction without its Coulomb-like terms
            rest = out[f"v{v}_resting"]
            centre = pred if comp.centre is None else comp.centre.get(label, pred)
            out[f"v{v}_{label}"] = np.where(rest, centre, pred)
    OUT.mkdir(exist_ok=True)
    np.savez(OUT / f"{name}_{tag}.npz", **out)
    print(f"{name} {tag}: main {result.main}; truth " + ", ".join(f"{c} {yard[labels[c]]:.2f}" for c in labels), flush=True)


CANDIDATES = ("ls", "sdp", "drive", "nominal")


def features(path: Path) -> dict:
    """What a torque-free rule may read of one collected case: per candidate the block jackknife's spread of its
    predictions on the validation logs' states (``J``, % of the nominal model's predicted RMS torque), the pairwise
    RMS differences of the candidates' predictions there (``D``, same unit), the identification log's held-out block
    error (``held``, % of its RMS torque); and, to judge by only, ``truth`` (the one yardstick's mean global errors)
    and ``chosen`` (what the verdict, which reads the validation torques, chose)."""
    z = np.load(path)
    labels, truth = json.loads(str(z["labels"])), json.loads(str(z["truth"]))
    spread: dict = {c: [] for c in CANDIDATES}
    apart: dict = {}
    weight = []
    for v in range(len([k for k in z.files if k.endswith("_measured")])):
        pred = {c: z[f"v{v}_{c}"] for c in CANDIDATES}
        scale = np.sqrt(np.mean(pred["nominal"] ** 2))
        weight.append(pred["nominal"].size)
        for c in CANDIDATES:
            refits = np.array([z[f"v{v}_{c}#{k}"] for k in range(FOLDS)])
            spread[c].append(100 * np.sqrt((FOLDS - 1) / FOLDS * np.sum(np.mean((refits - refits.mean(0)) ** 2, axis=(1, 2)))) / scale)
        for a in CANDIDATES:
            for b in CANDIDATES:
                apart.setdefault((a, b), []).append(100 * np.sqrt(np.mean((pred[a] - pred[b]) ** 2)) / scale)
    avg = lambda x: float(np.average(x, weights=weight))  # noqa: E731
    chosen = next((c for c in CANDIDATES if labels[c] == str(z["main"])), "nominal")
    return {"truth": truth, "chosen": chosen, "J": {c: avg(spread[c]) for c in CANDIDATES},
            "D": {k: avg(v) for k, v in apart.items()},
            "held": dict(zip(CANDIDATES, 100 * z["held"] / float(z["tau_rms_fit"])))}


def significance_rule(z: float, sensor_joint: bool = False):
    """The rule measured: the SDP where its predictions on the validation states differ from the drive-only
    estimate's by more than ``z`` times its own jackknife spread there (the links the log found are not the
    description's, beyond what the log can tell); else the drive-only estimate where it differs from the nominal
    model by more than ``z`` times its spread; else the description. With ``sensor_joint``, a joint torque sensor's
    log has no drive-only candidate."""
    def rule(o: dict, joint: bool = False) -> str:
        J, D = o["J"], o["D"]
        other = "nominal" if joint and sensor_joint else "drive"
        if D[("sdp", other)] > z * J["sdp"]:
            return "sdp"
        if other == "drive" and D[("drive", "nominal")] > z * J["drive"]:
            return "drive"
        return "nominal"
    return rule


def fallback_rule(z: float):
    """The SDP where its predictions on the validation states differ from the fallback's by more than ``z`` times its
    own jackknife spread there, else the fallback: the description's rigid body with what a short log determines
    well, its drive terms (drive-only) on a motor-side log, nothing (the description) on a joint torque sensor's."""
    def rule(o: dict, joint: bool = False) -> str:
        fallback = "nominal" if joint else "drive"
        return "sdp" if o["D"][("sdp", fallback)] > z * o["J"]["sdp"] else fallback
    return rule


def evaluate() -> int:
    """The rules on what ``--collect`` stored: exceptions to "never worse than the description by more than 2 %"
    and the chosen estimate against the best of the four, both on the one yardstick."""
    cases = {p.stem: features(p) for p in sorted(OUT.glob("*.npz"))}
    if not cases:
        print(f"nothing collected in {OUT}: run with --collect first")
        return 1
    rules = {"the verdict (reads the validation torques)": lambda o, j: o["chosen"], "always the SDP": lambda o, j: "sdp"}
    rules.update({f"significance, z = {z:g}": (lambda o, j, r=significance_rule(z): r(o, j)) for z in (1.5, 2.0, 2.5, 3.0)})
    rules.update({f"significance, z = {z:g}, no drive-only with a joint torque sensor":
                  (lambda o, j, r=significance_rule(z, True): r(o, j)) for z in (2.0, 2.5, 3.0)})
    rules.update({f"fallback by sensor, z = {z:g}": (lambda o, j, r=fallback_rule(z): r(o, j)) for z in (2.0, 2.5, 3.0)})
    print("rule | exceptions (worse than the description by > 2 %) | chosen / best of the four: worst, mean")
    for name, rule in rules.items():
        picks = {n: rule(o, n.startswith("kuka_med7")) for n, o in cases.items()}
        bad = [n for n, o in cases.items() if o["truth"][picks[n]] > 1.02 * o["truth"]["nominal"]]
        ratio = [o["truth"][picks[n]] / min(o["truth"].values()) for n, o in cases.items()]
        print(f"{name} | {len(bad)} ({', '.join(bad) or 'none'}) | {max(ratio):.2f}, {np.mean(ratio):.2f}")
    return 0


def product() -> int:
    """``[estimation] choice = "states"`` as dynid runs it, on the same 22 cases: the main estimate, its figure on the
    one yardstick against the description's, and the evidence it weighed."""
    import re

    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    folder = Path(tempfile.mkdtemp())
    bad, ratios = [], []
    print("case | main estimate (choice = states) | its % | description % | main / description | SDP apart / spread")
    for name, tag, window in _cases():
        path, root = _config_path(name, window, folder)
        path.write_text(re.sub(r"^\[estimation\]$", '[estimation]\nchoice = "states"', path.read_text(), count=1, flags=re.M))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = run_identification(load_identification_config(path, data_root=root))
        yard = result.diagnostics["yardstick"]["mean_global_relative_error"]
        nominal = result.diagnostics["nominal_set"]
        ratio = yard[result.main] / yard[nominal]
        ratios.append(ratio)
        if ratio > 1.02:
            bad.append(f"{name} {tag}")
        ev = result.diagnostics["state_evidence"]
        print(f"{name} {tag} | {result.main} | {yard[result.main]:.2f} | {yard[nominal]:.2f} | {ratio:.2f} | "
              f"{ev['ratio']:.2f}", flush=True)
    print(f"worse than the description by more than 2 %: {len(bad)} ({', '.join(bad) or 'none'})")
    return 0


def main() -> int:
    if "--product" in sys.argv[1:]:
        return product()
    if "--collect" in sys.argv[1:]:
        folder = Path(tempfile.mkdtemp())
        only = [a for a in sys.argv[1:] if not a.startswith("--")]
        for name, tag, window in _cases():
            if not only or f"{name}_{tag}" in only:
                collect(name, tag, window, folder)
        return 0
    return evaluate()


if __name__ == "__main__":
    sys.exit(main())
