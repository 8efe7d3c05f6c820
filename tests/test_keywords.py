"""Settings after the data are keyword-only in the public API (issue "Re-zone the top floors", item 7); a call that
still passes them by position works as before with a FutureWarning naming them."""

import inspect

import numpy as np
import pytest

import dynid
from dynid.keywords import keyword_only_after_data

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
