"""Results of every config in configs/, dynid run and Monte Carlo realisations against stored digests
(tests/digests.py): a restructuring meant to change nothing is checked to change nothing."""

import pytest
from threadpoolctl import threadpool_limits

from tests import digests

RENAMED = {
    # issue 23: one name for every estimate, one list of estimators
    "/method": "/least_squares",
    "/methods/": "/estimates/",
    "/physically_consistent/": "/estimates/dynid SDP/",
    "/settings/methods": "/settings/estimators",
}
"""Stored JSON path prefix -> today's, for keys a change renamed (the values must still agree)."""

DROPPED = ("/physically_consistent/label",)
"""Stored paths no longer written: the physically consistent estimate's label is now its key in /estimates."""


@pytest.mark.parametrize("case", digests.CASES)
def test_results_agree_with_the_stored_digest(case, shipped_identification):
    stored = digests.load().get(case)
    if stored is None:
        pytest.fail(f"no stored digest for {case}: run python -m tests.digests {case}")
    if case.startswith("identify:") and digests.data_root(digests.ROOT / "configs" / f"{case.split(':')[1]}.toml") is None:
        pytest.skip(f"data of {case} not found (set DYNID_SHARED_DATA to the shared/data folder)")
    if case.startswith("identify:"):  # the run the other tests of that config read (one BLAS thread, as here)
        now = digests.flatten(digests.of_result(shipped_identification(case.split(":")[1])))
    else:
        with threadpool_limits(1):
            now = digests.flatten(digests.compute(case))
    diff = digests.differences(stored, now, RENAMED, DROPPED, solver=case == "montecarlo")
    assert not diff, f"{case}: {len(diff)} of {len(stored)} values differ, e.g.\n" + "\n".join(diff[:15])


def test_the_comparison_sees_a_changed_value_and_a_missing_key():
    stored = {"/a": 1.0, "/b": "x", "/c[0]": 2.0}
    assert digests.differences(stored, dict(stored)) == []
    assert digests.differences(stored, {**stored, "/a": 1.0 + 1e-5}) == ["/a: 1.0 -> 1.00001"]
    assert digests.differences(stored, {**stored, "/a": 1.0 + 1e-8}) == []  # another CPU's last digits
    assert digests.differences(stored, {"/a": 1.0, "/c[0]": 2.0}) == ["/b: missing"]
    assert digests.differences(stored, {"/a": 1.0, "/new/b": "x", "/c[0]": 2.0}, {"/b": "/new/b"}) == []
    assert digests.differences({"/ab": 1.0, "/a": 2.0}, {"/ab": 1.0, "/z": 2.0}, {"/a": "/z"}) == []  # "/a" is not "/ab"


def test_a_design_is_compared_on_its_criterion_and_the_rest_exactly():
    stored = {"/design/cond": 20.0, "/design/nit": 311, "/design/initial_cond": 63.86, "/trajectory/a[0][0]": 0.58,
              "/limits/q_max[0]": 2.96, "/set_points/first[0]": 0.5, "/cell_clearance[0]/margin": 0.03,
              "/self_clearance/time": 1.0}
    moved = {**stored, "/design/nit": 250, "/trajectory/a[0][0]": -0.2, "/design/cond": 20.5,  # another optimum
             "/set_points/first[0]": -0.9, "/cell_clearance[0]/margin": 0.06, "/self_clearance/time": 9.8}
    assert digests.differences(stored, moved) == []
    assert digests.differences(stored, {**moved, "/design/cond": 25.0}) == ["/design/cond: 20.0 -> 25.0"]
    assert digests.differences(stored, {**moved, "/design/initial_cond": 80.0}) == ["/design/initial_cond: 63.86 -> 80.0"]
    assert digests.differences(stored, {**moved, "/limits/q_max[0]": 2.9}) == ["/limits/q_max[0]: 2.96 -> 2.9"]


def test_a_meaningless_correlation_and_a_pseudo_inertias_zero_are_compared_as_such():
    stored = {"/validation[0]/metrics/dynid OLS/correlation[0]": -0.007, "/validation[0]/metrics/dynid OLS/correlation[1]": 0.9,
              "/validation[0]/correlation_meaningful[0]": False, "/validation[0]/correlation_meaningful[1]": True,
              "/estimates/dynid SDP/pseudo_inertia_min_eig[0]": 5.6793e-07}
    moved = {**stored, "/validation[0]/metrics/dynid OLS/correlation[0]": -0.011, "/estimates/dynid SDP/pseudo_inertia_min_eig[0]": 5.6803e-07}
    assert digests.differences(stored, moved) == []
    assert digests.differences(stored, {**moved, "/validation[0]/metrics/dynid OLS/correlation[1]": 0.8}) == [
        "/validation[0]/metrics/dynid OLS/correlation[1]: 0.9 -> 0.8"]
    assert digests.differences(stored, {**moved, "/estimates/dynid SDP/pseudo_inertia_min_eig[0]": -1e-4}) == [
        "/estimates/dynid SDP/pseudo_inertia_min_eig[0]: 5.6793e-07 -> -0.0001"]


def test_the_comparison_allows_another_cpus_digits_and_nothing_more():
    """Each tolerance of tests/digests.py lets through what two CPUs' kernels were measured to move (a Zen 3 against a
    Zen 4) and flags a change ten times smaller than a real one."""
    sdp = "/estimates/dynid SDP/standard_values/"
    stored = {f"{sdp}M1": 3.0, f"{sdp}XX1": 0.07189410577888398, f"{sdp}fv1": 2.0386580735360316e-09,
              "/estimates/dynid WLS/values/fv1": 0.0123, "/consistency_margin/dynid SDP": -1.554626574708685e-08,
              "/diagnostics/bootstrap_std/MY2": 164413.39852469388, "/diagnostics/position_t[1]": 0.04665770085660343,
              "/settings/friction_models/out_of_fold_rms_error[13][5]": 49.68590919069535}
    measured = {f"{sdp}XX1": 0.07186426369692626, f"{sdp}fv1": 3.7e-10, "/consistency_margin/dynid SDP": -2.81e-08,
                "/diagnostics/bootstrap_std/MY2": 164417.40466010655, "/diagnostics/position_t[1]": 0.046654826174520506,
                "/settings/friction_models/out_of_fold_rms_error[13][5]": 54.45643018108679}
    assert digests.differences(stored, {**stored, **measured}) == []
    moved = {f"{sdp}M1": 3.003, f"{sdp}fv1": 0.003, "/estimates/dynid WLS/values/fv1": 0.0123 * (1 + 1e-5),
             "/consistency_margin/dynid SDP": -1e-5, "/diagnostics/bootstrap_std/MY2": 164413.39852469388 * 1.001,
             "/diagnostics/position_t[1]": 0.0467 * 1.001, "/settings/friction_models/out_of_fold_rms_error[13][5]": 60.0}
    for path, value in moved.items():
        assert [d.split(":")[0] for d in digests.differences(stored, {**stored, path: value})] == [path], path
