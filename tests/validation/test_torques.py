"""Fit metrics from accumulated sums equal those of the stored torques (one pass over a log instead of two)."""

import numpy as np

from dynid.validation.torques import TorqueComparison, TorqueSums


def test_metrics_from_sums_equal_metrics_from_the_samples():
    rng = np.random.default_rng(0)
    m, n, p = 7_000, 3, 5
    y = rng.standard_normal((m, n, p))
    beta = rng.standard_normal(p)
    tau = y @ beta + 0.3 * rng.standard_normal((m, n)) + np.array([50.0, -2.0, 0.0])  # offsets: centring matters
    t = np.arange(m) * 0.01
    sets = {"a": beta, "b": beta + 0.1 * rng.standard_normal(p)}
    sums = TorqueSums(n, p, m, max_points=2500)
    for a in range(0, m, 1234):  # in chunks, as the regressor pass gives them
        sums.add(t[a:a + 1234], y[a:a + 1234], tau[a:a + 1234])
    got = sums.comparison("x", sets)
    full = TorqueComparison("x", t, tau, {k: y @ b for k, b in sets.items()})
    for label in sets:
        for key, value in full.metrics()[label].items():
            np.testing.assert_allclose(got.metrics()[label][key], value, rtol=1e-9)
    assert got.n_samples == m and np.allclose(got.rms_torque, full.rms_torque)
    step = -(-m // 2500)  # the figure's thinning: the same points as thinning all samples
    np.testing.assert_array_equal(got.t, t[::step])
    np.testing.assert_allclose(got.predicted["b"], (y @ sets["b"])[::step])
    assert got.to_dict()["n_samples"] == m


def test_metrics_from_sums_hold_for_a_log_at_rest():
    """Almost constant rows and torques (a pose held): raw sums would cancel, the centred statistics do not."""
    rng = np.random.default_rng(1)
    m, n, p = 4_000, 2, 3
    y = 100.0 + 1e-4 * rng.standard_normal((m, n, p))
    beta = np.array([1.0, -0.5, 0.25])
    tau = 75.0 + 1e-4 * rng.standard_normal((m, n))
    t = np.arange(m) * 0.01
    sums = TorqueSums(n, p, m)
    for a in range(0, m, 1000):
        sums.add(t[a:a + 1000], y[a:a + 1000], tau[a:a + 1000])
    got = sums.comparison("rest", {"b": beta}).metrics()["b"]
    full = TorqueComparison("rest", t, tau, {"b": y @ beta}).metrics()["b"]
    for key, value in full.items():
        np.testing.assert_allclose(got[key], value, rtol=1e-6, err_msg=key)


def test_the_rows_kept_for_the_figure_do_not_hold_the_chunks():
    """The statistics keep every ``thin``-th row for the figure as copies: a view would keep each whole chunk
    (the regressor rows of the whole log) alive, and the identification's memory would grow with the log."""
    rng = np.random.default_rng(1)
    sums = TorqueSums(2, 4, 40_000, max_points=100)
    chunks = [(np.arange(4000) * 1e-3, rng.standard_normal((4000, 2, 4)), rng.standard_normal((4000, 2))) for _ in range(3)]
    for t, y, tau in chunks:
        sums.add(t, y, tau)
    kept = sums.kept_t + sums.kept_y + sums.kept_tau
    assert not any(np.shares_memory(k, c) for k in kept for chunk in chunks for c in chunk)
    assert sum(k.nbytes for k in kept) < sum(c.nbytes for chunk in chunks for c in chunk) / 100


def test_moving_and_resting_samples_are_scored_apart():
    """Where a joint rests, the figures are those of its resting samples (RMSE, share inside ±f_s), and where it
    moves those of its moving samples, each computed directly here; the accumulated sums of the fit agree."""
    rng = np.random.default_rng(2)
    m, n, p = 3_000, 2, 4
    y = rng.standard_normal((m, n, p))
    beta = rng.standard_normal(p)
    resting = np.zeros((m, n), dtype=bool)
    resting[1000:1600, 0] = True
    tau = y @ beta + 0.2 * rng.standard_normal((m, n))
    tau[resting] += rng.uniform(-1.5, 1.5, resting.sum())  # the static friction: anything within ±1.5 N·m
    pred = y @ beta
    cmp = TorqueComparison("x", np.arange(m) * 0.01, tau, {"b": pred}, resting=resting, static={"b": np.array([1.5, 1.0])})
    got = cmp.metrics()["b"]
    err = tau - pred
    mov = ~resting[:, 0]
    np.testing.assert_allclose(got["moving_rmse"][0], np.sqrt((err[mov, 0] ** 2).mean()))
    np.testing.assert_allclose(got["moving_relative_error"][0], 100 * np.linalg.norm(err[mov, 0]) / np.linalg.norm(tau[mov, 0]))
    np.testing.assert_allclose(got["rest_rmse"][0], np.sqrt((err[~mov, 0] ** 2).mean()))
    assert got["rest_in_static_band"][0] == np.mean(np.abs(err[~mov, 0]) <= 1.5 * 1.05) > 0.9
    assert np.isnan(got["rest_rmse"][1]) and cmp.rest_share.tolist() == [0.2, 0.0]
    sums = TorqueSums(n, p, m)
    for a in range(0, m, 700):
        sums.add(cmp.t[a:a + 700], y[a:a + 700], tau[a:a + 700], resting[a:a + 700])
    acc = sums.comparison("x", {"b": beta}).metrics()["b"]
    for key in ("moving_rmse", "moving_relative_error", "rest_rmse"):
        np.testing.assert_allclose(acc[key][0], got[key][0], rtol=1e-8, err_msg=key)


def test_a_joint_at_the_noise_level_is_flagged_with_its_absolute_error():
    from dynid.report.summaries import comparison_table

    rng = np.random.default_rng(3)
    m = 500
    tau = np.column_stack([50 + 10 * np.sin(np.arange(m) / 30), 0.05 * rng.standard_normal(m)])
    pred = tau + 0.3 * rng.standard_normal((m, 2))
    cmp = TorqueComparison("p1", np.arange(m) * 0.01, tau, {"b": pred}, noise=np.array([0.5, 0.3]),
                           speed=np.array([0.4, 0.001]))
    assert cmp.meaningful().tolist() == [True, False]
    (flag,) = cmp.flags()
    assert flag.startswith("p1: J2 barely moves") and "relative error not meaningful" in flag and "RMSE 0.3" in flag
    table = comparison_table(cmp)
    error_row = next(r for r in table.rows if r[0].strip() == "error %")
    assert error_row[1] != "n/m" and error_row[2] == "n/m"
    assert cmp.to_dict()["relative_error_meaningful"] == [True, False]


def test_a_prediction_that_is_rounding_of_zero_has_no_correlation():
    """The TX40's nominal torque of joint 6 is 0 in exact arithmetic and 4e-17 N·m in floating point: its correlation
    with the measured torque was ±0.254, its sign set by the last digits. Here the prediction of joint 2 is
    ``0.1·3·x - 0.3·x``: rounding that follows the signal, so Pearson's formula gives 0.74."""
    rng = np.random.default_rng(2)
    m = 3_000
    x = rng.standard_normal(m)
    y = np.zeros((m, 2, 2))
    y[:, 0] = rng.standard_normal((m, 2))
    y[:, 1, 0], y[:, 1, 1] = 0.1 * x, 0.3 * x
    beta = np.array([3.0, -1.0])
    p = y @ beta
    assert 0 < np.abs(p[:, 1]).max() < 1e-15 and abs(np.corrcoef(p[:, 1], x)[0, 1]) > 0.5  # what made it look defined
    tau = p + np.column_stack([0.1 * rng.standard_normal(m), x])
    sums = TorqueSums(2, 2, m)
    sums.add(np.arange(m) * 0.01, y, tau)
    for rho in (sums.comparison("x", {"b": beta}).metrics()["b"]["correlation"],
                TorqueComparison("x", np.arange(m) * 0.01, tau, {"b": p}).metrics()["b"]["correlation"]):
        assert rho[0] > 0.99 and np.isnan(rho[1])


def test_a_set_left_out_leaves_the_others_as_if_it_had_never_been_scored():
    """A candidate scored beside the others and then left out (``without``): every other set's metrics, curves and
    static friction are those of a comparison that never had it, from the sums and from the samples."""
    rng = np.random.default_rng(3)
    m, n, p = 2_000, 2, 4
    y = rng.standard_normal((m, n, p))
    tau = y @ rng.standard_normal(p) + 0.2 * rng.standard_normal((m, n))
    t = np.arange(m) * 0.01
    sets = {"a": rng.standard_normal(p), "b": rng.standard_normal(p)}
    resting = np.zeros((m, n), dtype=bool)
    resting[500:700] = True
    static = {"a": np.array([0.5, 0.2]), "b": np.array([0.1, 0.3])}
    full = TorqueComparison("x", t, tau, {k: y @ v for k, v in sets.items()}, resting=resting, static=static,
                            centre={k: y @ v - 0.1 for k, v in sets.items()}, band=static["a"]).without("b")
    alone = TorqueComparison("x", t, tau, {"a": y @ sets["a"]}, resting=resting, static={"a": static["a"]},
                             centre={"a": y @ sets["a"] - 0.1}, band=static["a"])
    assert list(full.metrics()) == ["a"] == list(full.predicted) == list(full.static) == list(full.centre)
    for key, value in alone.metrics()["a"].items():
        np.testing.assert_array_equal(full.metrics()["a"][key], value, err_msg=key)
    sums = TorqueSums(n, p, m)
    sums.add(t, y, tau, resting)
    kept = sums.comparison("x", sets).without("b")
    assert list(kept.metrics()) == list(kept.predicted) == ["a"]
    for key, value in sums.comparison("x", {"a": sets["a"]}).metrics()["a"].items():
        np.testing.assert_array_equal(kept.metrics()["a"][key], value, err_msg=key)


def test_each_sets_metrics_are_computed_once_and_a_callers_change_stays_its_own(monkeypatch):
    """The evidence and the verdict read a log's metrics many times (83 reads of 37 sets on the TX40's config): each set
    is scored once per comparison, the same figures each time, and a comparison made from it scores afresh."""
    import dynid.validation.torques as torques

    rng = np.random.default_rng(5)
    t = np.arange(500) * 0.01
    measured = rng.standard_normal((500, 3))
    sets = {"a": measured + 0.1, "b": measured - 0.2 * rng.standard_normal((500, 3))}
    expected = TorqueComparison("x", t, measured, sets).metrics()
    cmp = TorqueComparison("x", t, measured, sets)
    calls = []
    real = torques.relative_error
    monkeypatch.setattr(torques, "relative_error", lambda m, p: calls.append(1) or real(m, p))
    first = cmp.metrics()
    first["a"]["global_relative_error"] = -1.0  # a caller's change to what it was given
    again = cmp.metrics()
    assert len(calls) == 2  # one per set, not one per read
    for label in sets:
        assert again[label].keys() == expected[label].keys()
        for key, value in expected[label].items():
            np.testing.assert_array_equal(again[label][key], value)
    assert list(cmp.without("b").metrics()) == ["a"] and len(calls) == 3  # made from it: scored afresh
