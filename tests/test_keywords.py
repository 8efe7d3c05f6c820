"""Settings after the data are keyword-only in the public API (issue "Re-zone the top floors", item 7); a call that
still passes them by position works as before with a FutureWarning naming them."""

import inspect

import numpy as np
import pytest

import dynid
from dynid._util.keywords import keyword_only_after_data
from dynid.exceptions import ConfigError

DATA = {"q", "dq", "ddq", "tau", "t", "phi", "q_rest", "config"}
"""Optional arguments that are data (a log's arrays, parameters, the experiment's config), positional by design."""
SELECTORS = {("parameters", "estimate"), ("params", "estimate"), ("label", "estimate"), ("get_params", "deep")}
"""One optional argument that picks what to return (scikit-learn's ``get_params(deep)``, ``parameters("ols")``)."""


def _public_callables():
    for name in dynid.__all__:
        obj = getattr(dynid, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj):
            for member, f in vars(obj).items():
                if inspect.isfunction(f) and not member.startswith("_"):
                    yield f"{name}.{member}", f


def test_every_setting_of_the_public_api_is_keyword_only():
    positional = []
    for name, f in _public_callables():
        for p in inspect.signature(inspect.unwrap(f)).parameters.values():
            if (p.kind is p.POSITIONAL_OR_KEYWORD and p.default is not p.empty and p.name not in DATA
                    and (name.rsplit(".", 1)[-1], p.name) not in SELECTORS):
                positional.append(f"{name}({p.name})")
    assert not positional, f"settings that can still be given by position: {positional}"


def test_a_setting_by_position_still_works_with_a_warning_naming_it():
    robot = dynid.load_robot("er16")
    q, dq, ddq = (np.random.default_rng(k).uniform(-1, 1, (5, robot.n_dof)) for k in range(3))
    cols = np.arange(4)
    by_name = dynid.regressor(robot, q, dq, ddq, columns=cols)
    with pytest.warns(FutureWarning, match=r"regressor: pass columns=\.\.\. by name; by position it is refused"):
        by_position = dynid.regressor(robot, q, dq, ddq, cols)
    np.testing.assert_array_equal(by_position, by_name)


def test_too_many_or_doubled_arguments_are_the_usual_type_errors():
    @keyword_only_after_data
    def f(x, *, a=1, b=2):
        return x + a + b

    with pytest.warns(FutureWarning, match=r"pass a=\.\.\., b=\.\.\. by name"):
        assert f(1, 10, 100) == 111
    with pytest.raises(TypeError, match="takes 1 positional arguments but 4 were given"):
        f(1, 2, 3, 4)
    with pytest.raises(TypeError, match="got multiple values for argument 'a'"):
        f(1, 2, a=3)
    assert f(1, b=5) == 7


def test_the_random_state_has_one_name_and_the_former_one_still_works_with_a_warning():
    """issue "Parts carry their settings, one route", item 6: every public callable that takes a random state calls
    it ``rng`` (NumPy's SPEC 7: an int or a Generator); ``seed=`` of those 0.1.0 had gives the same result with a
    FutureWarning naming ``rng``, and both at once are refused. A config's ``seed`` key (a user's file) is unchanged."""
    from dynid.estimators import check_estimator
    from dynid.identification.pipeline import IdentificationPipeline
    from dynid.studies.simulated_fleet import simulate_fleet, simulate_service_life

    callables = [*(f for _, f in _public_callables()), dynid.Identifier.__init__, IdentificationPipeline.__init__,
                 check_estimator, simulate_fleet, simulate_service_life]
    named = {p for f in callables for p in inspect.signature(f).parameters}
    assert "rng" in named and "seed" not in named
    robot = dynid.load_robot("er16")
    log = dynid.simulated_log(robot, seconds=2, rng=3)
    with pytest.warns(FutureWarning, match="seed= is now rng="):
        old = dynid.simulated_log(robot, seconds=2, seed=3)
    np.testing.assert_array_equal(old.tau, log.tau)
    assert old.name == log.name == "simulated er16, seed 3"
    drawn = dynid.simulated_log(robot, seconds=2, rng=np.random.default_rng(3))  # a generator: SPEC 7
    np.testing.assert_array_equal(drawn.tau, log.tau)
    with pytest.raises(TypeError, match="give rng= only"):
        dynid.simulated_log(robot, seconds=2, seed=3, rng=3)
    with pytest.warns(FutureWarning, match="seed= is now rng="):
        ident = dynid.Identifier(robot, seed=4)
    assert ident.get_params()["rng"] == 4 and "seed" not in ident.get_params()
    # seed= of callables no release had (an earlier 0.2.0 draft's): refused as any unknown keyword
    with pytest.raises(TypeError, match="unexpected keyword argument 'seed'"):
        IdentificationPipeline(robot, seed=5)
    with pytest.raises(TypeError, match="unexpected keyword argument 'seed'"):
        check_estimator("ols", seed=1)
    with pytest.raises(ConfigError, match="unknown setting 'seed'"):
        dynid.identify_from_arrays(robot, log.t, log.q, log.tau, seed=1)


def test_a_negative_seed_and_a_log_of_no_samples_are_refused_in_one_line():
    """NumPy refused a negative seed deep in an estimator ("expected non-negative integer", no field named), and a
    simulated log of 0 s or of a negative rate was made in silence."""
    robot = dynid.load_robot("er16")
    log = dynid.simulated_log(robot, seconds=2, rng=3)
    with pytest.raises(ConfigError, match=r"^rng: expected a seed >= 0 \(or a numpy.random.Generator\), got -1$"):
        dynid.identify_from_arrays(robot, log.t, log.q, log.tau, estimators=("ols",), rng=-1)
    with pytest.raises(ConfigError, match=r"^rng: expected a seed >= 0"):
        dynid.simulated_log(robot, seconds=2, rng=-2)
    for seconds, rate in ((0.0, 250.0), (2.0, -1.0), (float("nan"), 250.0), (0.004, 250.0)):
        with pytest.raises(ConfigError, match=r"^simulated_log: expected a positive length and rate"):
            dynid.simulated_log(robot, seconds=seconds, rate=rate)
    assert dynid.simulated_log(robot, seconds=0.008, rate=250.0).t.size == 2
