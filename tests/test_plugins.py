"""The user's own estimators and strategies from the command line: ``--plugin FILE``, ``DYNID_PLUGINS`` and the
``dynid.plugins`` entry points (dynid.plugins), in dynid run, identify and a Monte Carlo study's Dask workers."""

import json
import sys
import textwrap

import numpy as np
import pytest

from dynid import plugins
from dynid.cli.app import main
from dynid.estimators import registry
from dynid.preprocessing import strategies

RIDGE = textwrap.dedent('''
    import numpy as np
    from dynid.estimators import Estimator, register

    class Ridge(Estimator):
        def __init__(self, *, alpha: float = 1e-9):
            self.alpha = alpha

        def fit(self, w, tau):
            gram = w.T @ w
            scale = self.alpha * np.trace(gram) / gram.shape[0]
            self.params_ = np.linalg.solve(gram + scale * np.eye(gram.shape[0]), w.T @ np.ravel(tau))
            return self

    register("{key}", Ridge, label="Ridge plugin", description="ridge regression from a plugin file")
''')


@pytest.fixture
def clean(monkeypatch):
    """Each test's plugins forgotten afterwards: registrations, modules, the environment."""
    monkeypatch.delenv(plugins.ENVIRONMENT, raising=False)
    before = (dict(registry._REGISTRY), dict(strategies._STRATEGIES), dict(plugins._LOADED), set(sys.modules))
    yield
    registry._REGISTRY.clear(), registry._REGISTRY.update(before[0])
    strategies._STRATEGIES.clear(), strategies._STRATEGIES.update(before[1])
    plugins._LOADED.clear(), plugins._LOADED.update(before[2])
    for name in set(sys.modules) - before[3]:
        if name.startswith("ridge_plugin") or name.startswith("my_plugins"):
            del sys.modules[name]


def _ridge_file(folder, key="ridge_plugin"):
    path = folder / f"{key}.py"
    path.write_text(RIDGE.format(key=key))
    return path


RUN = ["--bootstrap", "0", "--duration", "10", "--rate", "200", "--current-noise", "0", "--no-figures", "-q"]


def test_a_plugin_file_adds_an_estimator_to_dynid_run(tmp_path, clean):
    path = _ridge_file(tmp_path)
    out = tmp_path / "run"
    assert main(["--plugin", str(path), "run", "--estimators", "ols,ridge_plugin", "--out", str(out), *RUN]) == 0
    stored = json.loads((out / "results.json").read_text())
    ridge, ols = stored["estimates"]["ridge_plugin"], stored["estimates"]["ols"]
    assert ridge["label"] == "Ridge plugin"
    # a tiny ridge: OLS's estimate
    expected = np.array(list(ols["params"].values()))
    np.testing.assert_allclose(list(ridge["params"].values()), expected, rtol=1e-4, atol=1e-6 * np.abs(expected).max())


def test_the_environment_names_plugins_for_a_config(tmp_path, clean, monkeypatch):
    from .simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "ur10e", 125.0, "fourier", seed=4, duration=20.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["ridge_plugin", "ols"]'))
    monkeypatch.setenv(plugins.ENVIRONMENT, str(_ridge_file(tmp_path)))
    assert main(["identify", str(cfg), "--out", str(tmp_path / "out"), "-q"]) == 0
    stored = json.loads((tmp_path / "out" / "results.json").read_text())
    assert stored["main_estimate"] == "dynid Ridge plugin"


def test_an_entry_point_is_loaded_when_its_name_is_asked_for(tmp_path, clean, monkeypatch):
    from importlib.metadata import EntryPoint

    (tmp_path / "my_plugins_ep.py").write_text(RIDGE.format(key="ridge_ep"))
    monkeypatch.syspath_prepend(str(tmp_path))
    point = EntryPoint(name="ridge", value="my_plugins_ep", group=plugins.ENTRY_POINT_GROUP)
    monkeypatch.setattr("importlib.metadata.entry_points", lambda group=None: [point] if group == plugins.ENTRY_POINT_GROUP else [])
    assert "ridge_ep" not in registry.keys()
    assert registry.parse_estimators("ols,RIDGE_EP") == ("ols", "ridge_ep")


def test_a_plugin_runs_in_a_monte_carlo_studys_dask_worker(tmp_path, clean, capsys):
    """The file is uploaded to the workers (they are other processes that never imported it)."""
    path = _ridge_file(tmp_path)
    out = tmp_path / "mc"
    assert main(["--plugin", str(path), "montecarlo", "--estimators", "ols,ridge_plugin", "--realisations", "2",
                 "--noise-levels", "0.05", "--duration", "8", "--rate", "100", "--workers", "1", "--out", str(out), "-q"]) == 0
    stored = json.loads((out / "montecarlo.json").read_text())
    assert stored["settings"]["estimators"] == ["ols", "ridge_plugin"] and list(stored["estimates"]) == ["ols", "ridge_plugin"]
    assert stored["errors"] == []


@pytest.mark.parametrize("content, message", [
    (None, r"plugin .*missing\.py \(--plugin .*\): no such file"),
    ("raise RuntimeError('boom')\n", r"plugin .*broken\.py \(--plugin .*\): cannot import it: RuntimeError: boom"),
])
def test_a_plugin_that_cannot_be_imported_is_one_line(tmp_path, clean, capsys, content, message):
    name = "missing.py" if content is None else "broken.py"
    if content is not None:
        (tmp_path / name).write_text(content)
    assert main(["--plugin", str(tmp_path / name), "run"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert __import__("re").search(message, err), err


def test_an_estimator_registered_again_by_the_same_class_is_no_conflict(clean):
    class Twice:
        pass

    registry.register("twice_test", Twice)
    registry.register("twice_test", Twice)  # the same class: a plugin imported again
    with pytest.raises(ValueError, match="registered already"):
        registry.register("twice_test", dict)


MISBEHAVING = {
    "wrong_length": ("self.params_ = np.zeros(w.shape[1] - 1)",
                     r"estimator misbehaving_wrong_length \(plugin misbehaving_wrong_length\.Odd\): returned parameters of "
                     r"shape \(\d+,\), expected \(\d+,\)"),
    "raises": ("raise RuntimeError('my solver diverged')",
               r"estimator misbehaving_raises \(plugin misbehaving_raises\.Odd\): its fit raised RuntimeError: my solver "
               "diverged"),
    "nan": ("self.params_ = np.full(w.shape[1], np.nan)",
            r"estimator misbehaving_nan \(plugin misbehaving_nan\.Odd\): returned \d+ NaN or infinite parameter"),
}


@pytest.mark.parametrize("case", sorted(MISBEHAVING))
def test_a_plugin_estimator_that_misbehaves_is_one_line_naming_it(tmp_path, clean, capsys, case):
    """A plugin whose fit raises (a 160-line traceback), returns the wrong number of parameters (a matmul error) or
    NaN (which became the main estimate): one line naming the estimator, its plugin and what it did; exit 1."""
    body, message = MISBEHAVING[case]
    key = f"misbehaving_{case}"
    path = tmp_path / f"{key}.py"
    path.write_text(textwrap.dedent(f'''
        import numpy as np
        from dynid.estimators import Estimator, register

        class Odd(Estimator):
            def fit(self, w, tau):
                {body}
                return self

        register("{key}", Odd)
    '''))
    code = main(["--plugin", str(path), "run", "--estimators", f"ols,{key}", "--out", str(tmp_path / "run"), *RUN])
    err = capsys.readouterr().err.strip()
    assert code == 1 and len(err.splitlines()) == 1, err
    assert re_search(message, err), err


def test_a_plain_estimator_cannot_replace_the_least_squares_reference(tmp_path, clean, capsys):
    path = tmp_path / "plain_wls.py"
    path.write_text(textwrap.dedent('''
        import numpy as np
        from dynid.estimators import Estimator, register

        class Plain(Estimator):
            def fit(self, w, tau):
                self.params_ = np.linalg.lstsq(w, np.ravel(tau), rcond=None)[0]
                return self

        register("wls", Plain, replace=True)
    '''))
    code = main(["--plugin", str(path), "run", "--estimators", "wls", "--out", str(tmp_path / "run"), *RUN])
    err = capsys.readouterr().err.strip()
    assert code == 1 and len(err.splitlines()) == 1, err
    assert "estimator wls (plugin plain_wls.Plain): replaces the least-squares reference" in err


def test_a_missing_plugin_in_the_environment_names_the_variable_and_the_file(tmp_path, clean, monkeypatch, capsys):
    from .simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", duration=8.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["ols", "someones_ridge"]'))
    monkeypatch.setenv(plugins.ENVIRONMENT, str(tmp_path / "missing.py"))
    assert main(["identify", str(cfg), "--out", str(tmp_path / "out"), "--no-figures", "-q"]) == 1
    err = capsys.readouterr().err
    assert f"plugin {tmp_path / 'missing.py'} (from DYNID_PLUGINS): no such file" in err


def re_search(pattern, text):
    import re

    return re.search(pattern, text) is not None
