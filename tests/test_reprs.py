"""What a researcher sees at a prompt (issue "Parts carry their settings, one route", item 6: a result's repr fits a
screen): the records of an identification and a design show their fields on one line, arrays by their shape."""

from dataclasses import dataclass

import numpy as np
import pytest

import dynid
from dynid._util.reprs import short_repr, short_value
from dynid.excitation.design import ExcitationProblem, design_excitation
from dynid.identification.pipeline import IdentificationPipeline

SCREEN = 600
"""Characters: about eight lines of a notebook's output."""


def test_a_value_is_shown_by_its_shape_or_its_length_when_it_is_long():
    assert short_value(np.zeros((3, 2))) == "<array (3, 2)>" and short_value(np.float64(0.1234567891)) == "0.123457"
    assert short_value(("ZZ1R", "fc1")) == "('ZZ1R', 'fc1')" and short_value(tuple(f"p{i}" for i in range(40))) == "<tuple of 40 str>"
    assert short_value({"a": np.zeros(400)}) == "<dict of 1 ndarray>" and short_value({"a": 1}) == "{'a': 1}"

    @short_repr
    @dataclass(frozen=True)
    class Inner:
        x: np.ndarray

    @short_repr
    @dataclass(frozen=True)
    class Outer:
        name: str
        inner: Inner

    assert repr(Outer("a", Inner(np.ones(1000)))) == "Outer(name='a', inner=Inner(x=<array (1000,)>))"


@pytest.fixture(scope="module")
def fitted():
    robot = dynid.load_robot("er16")
    log = dynid.simulated_log(robot, seconds=6.0, rng=0)
    pipeline = IdentificationPipeline(robot, estimators=("wls", "sdp"))
    prepared = pipeline.prepare(log)
    return robot, log, pipeline, prepared, pipeline.fit(log)


def test_the_records_of_an_identification_fit_a_screen(fitted):
    robot, log, pipeline, prepared, result = fitted
    records = {"robot": robot, "log": log, "pipeline": pipeline, "prepared": prepared, "data": prepared.data,
               "choices": prepared.choices, "base": prepared.base, "estimate": result.estimates["dynid SDP"],
               "fit": result.fit, "solution": result.solution, "drive-only": result.drive_only}
    for name, record in records.items():
        text = repr(record)
        assert "\n" not in text and len(text) <= SCREEN, (name, len(text), text[:200])
    assert "inertial=<array (6, 10)>" in repr(robot) and f"q=<array {log.q.shape}>" in repr(log)


def test_a_design_fits_a_screen():
    problem = ExcitationProblem(dynid.load_robot("er16"), 2 * np.pi * 0.1, 2)
    design = design_excitation(problem, n_starts=1, rng=0, maxiter=5)
    for record in (problem, design, design.trajectory):
        text = repr(record)
        assert "\n" not in text and len(text) <= SCREEN, text[:200]
    assert "margins=<list of " in repr(design) and "a=<array (6, 2)>" in repr(design.trajectory)


def test_a_design_made_from_the_library_has_a_summary():
    """dynid.summary(design) refused a design made by design_excitation ("expected a result of dynid, got
    ExcitationDesign"): it says the criterion before and after, the margins and whether every constraint holds."""
    problem = ExcitationProblem(dynid.load_robot("er16"), 2 * np.pi * 0.1, 2)
    design = design_excitation(problem, n_starts=1, rng=0, maxiter=5)
    text = dynid.summary(design, width=300)
    assert text.startswith("excitation design — criterion cond") and "Constraint margins on the verification grid" in text
    last = text.rstrip().splitlines()[-1]
    assert design.feasible and last.startswith(f"cond(W_base) {design.initial_cond:.2f} → {design.cond:.2f}")
    assert "every constraint holds, the tightest: " in last


def test_a_models_validation_has_a_summary(fitted):
    """dynid.summary(model.validate(log)) (a TorqueComparison, or a list of them) says what dynid validate says."""
    from dynid.identification.fitted_model import IdentifiedModel

    robot, log, _, _, result = fitted
    comparison = IdentifiedModel.from_result(result).validate(dynid.simulated_log(robot, seconds=4.0, rng=1))
    text = dynid.summary(comparison, width=300)
    assert text.startswith("In short (the tables follow)") and f"{comparison.name}: torque error over all joints: " in text
    assert dynid.summary([comparison, comparison], width=300).count(f"{comparison.name}: torque error") == 2


def test_a_closed_loop_setup_fits_a_screen():
    """A setup holding its set-points as an array (Identifier(controller=...)) printed the array over seven lines."""
    from dynid.simulation.closed_loop import ClosedLoopSetup, Controller

    robot = dynid.load_robot("er16")
    text = repr(ClosedLoopSetup(Controller.for_robot(robot), np.zeros((5000, 6)), feedforward=True))
    assert "\n" not in text and len(text) <= SCREEN, text[:200]
    assert "reference=<array (5000, 6)>" in text and "feedforward=True" in text
