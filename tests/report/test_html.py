"""The one-file HTML report: every table and figure present, nothing fetched from elsewhere."""

from html.parser import HTMLParser

from ..cli.test_cli import dynid


class _Parts(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tables, self.images, self.external, self.text = 0, [], [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table":
            self.tables += 1
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        for key in ("src", "href"):
            if key in attrs and not attrs[key].startswith(("data:", "#")):
                self.external.append(attrs[key])

    def handle_data(self, data):
        self.text.append(data)


def _parse(path):
    parts = _Parts()
    parts.feed(path.read_text(encoding="utf-8"))
    return parts


def test_run_and_identify_reports_hold_their_tables_and_figures(tmp_path):
    from ..simulated_logs import simulated_case

    p = dynid("run", "--estimators", "ols,abc", "--bootstrap", "0", "--duration", "4", "--out", str(tmp_path / "run"))
    assert p.returncode == 0, p.stderr
    report = _parse(tmp_path / "run" / "report.html")
    pngs = sorted((tmp_path / "run").glob("*.png"))
    assert len(report.images) == len(pngs) > 0 and all(src.startswith("data:image/png;base64,") for src in report.images)
    assert report.tables == 2 + 4 + 1 and not report.external  # estimators, parameters, 4 per-joint, timings
    text = " ".join(report.text)
    assert "0.3182" in text and "ABC" in text and "numpy" in text and "Pinocchio" in text

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', 'estimators = ["ols", "sdp"]\n'))
    p = dynid("identify", str(cfg), "--out", str(tmp_path / "id"))
    assert p.returncode == 0, p.stderr
    report = _parse(tmp_path / "id" / "report.html")
    n_logs = 2  # the identification log and the validation log
    # parameters, verdicts, one per log, and the files it wrote read back (the SDP passed its check)
    assert report.tables == 2 + n_logs + 1 and not report.external
    assert "The files you take away" in " ".join(report.text)
    assert len(report.images) == len(list((tmp_path / "id").glob("*.png"))) == n_logs
    text = " ".join(report.text)
    assert "truth" in text and "dynid SDP" in text and "excitation band" in text
    # a report for people: what it found first, a table of contents, values outside their range marked, real captions,
    # settings as people write them, and small (the figures scaled to the page, in few colours)
    html = (tmp_path / "id" / "report.html").read_text(encoding="utf-8")
    assert html.index('class="summary"') < html.index('id="settings"') < html.index('id="figures"')
    assert "Use dynid " in html and "torque error" in html[:html.index('id="settings"')]
    import re

    targets = set(re.findall(r'href="#([^"]+)"', html))
    assert targets and all(f'id="{t}"' in html for t in targets)
    assert "Measured and predicted torques on the identification log" in html
    assert "True" not in " ".join(report.text).split("Settings", 1)[1].split("Base parameters", 1)[0]
    import base64
    import io

    from PIL import Image

    from dynid.report.output import FIGURE_COLOURS

    for src in report.images:  # the figures are embedded in few colours (written so by save_figure)
        with Image.open(io.BytesIO(base64.b64decode(src.split(",", 1)[1]))) as image:
            assert image.mode == "P" and len(image.getcolors()) <= FIGURE_COLOURS


def test_values_outside_their_range_are_highlighted():
    from dynid.report.html import identify_sections
    from dynid.report.summaries import BAD_RELATIVE_STD

    d = {"robot": "r", "condition_number": 10.0, "n_rows": 100,
         "base_parameters": [{"name": "ZZ1R", "unit": "kg·m²", "value": 1.0, "std": 0.01, "relative_std_percent": 1.0, "expression": "ZZ1"},
                             {"name": "MX2", "unit": "kg·m", "value": 0.01, "std": 0.02, "relative_std_percent": 2 * BAD_RELATIVE_STD,
                              "expression": "MX2"}],
         "identification": {"name": "identification", "n_samples": 10, "relative_error_meaningful": [True, False],
                             "metrics": {"dynid WLS": {"relative_error": [80.0, 900.0], "rmse": [1.0, 1.0],
                                                       "correlation": [0.9, 0.1], "global_relative_error": 5.0}}},
         "main_estimate": "dynid WLS"}
    _, sections = identify_sections(d)
    params = next(s for s in sections if s.title == "Base parameters").tables[0]
    assert params.flagged == {(1, 4)}
    fit = next(s for s in sections if s.title.startswith("Measured")).tables[0]
    assert fit.flagged == {(0, 2)} and fit.rows[0][3] == "n/m"  # J2's torque is at the noise level: not flagged, n/m
    summary = next(s for s in sections if s.title == "In short").texts
    assert summary[1] == "identification: torque error 5 % over all joints, worst J1 80 % (the fit)."
    # the report's summary says what the terminal's does (one function): resting logs share one line
    resting = {"n_samples": 10, "relative_error_meaningful": [True, True], "rest_share": [1.0, 0.97],
               "metrics": {"dynid WLS": {"relative_error": [0.0, 0.0], "rmse": [0.0, 0.0],
                                         "correlation": [None, None], "global_relative_error": 0.0}}}
    d["validation"] = [{**resting, "name": "p1"}, {**resting, "name": "p2"}]
    _, sections = identify_sections(d)
    summary = next(s for s in sections if s.title == "In short").texts
    assert [t for t in summary if "rest" in t] == [
        "p1, p2 (2 logs at rest throughout): torque error 0 % over all joints (the distance to the static-friction "
        "band, a check of the gravity model to within friction, not of motion)."]


def test_the_report_says_a_flag_several_logs_share_once_and_what_export_writes():
    """The UR10e's ten resting logs each flagged "every joint at rest in 95 % of the log or more: …" (ten entries of
    the same words); and its summary said "Use dynid OLS, not physically consistent." where the terminal adds what
    dynid export writes instead."""
    from dynid.report.html import _identify_summary, said

    rest = "every joint at rest in 95 % of the log or more: the error there is the distance to the band"
    d = {"validation": [{"name": "p1", "flags": [f"p1: {rest}", "p1: J1 barely moves (RMS 1.3 N·m)"]},
                        {"name": "p2", "flags": [f"p2: {rest}", "p2: J1 barely moves (RMS 0.6 N·m)"]}],
         "warnings": ["a warning"], "main_estimate": "dynid OLS",
         "physically_consistent_verdict": {"dynid OLS": "no: an eigenvalue < 0", "dynid SDP": "yes"},
         "estimates": {"dynid OLS": {"values": {}}, "dynid SDP": {"values": {}, "standard_values": {"M1": 1.0}}}}
    assert said(d) == ["a warning", f"p1, p2: {rest}", "p1: J1 barely moves (RMS 1.3 N·m)",
                       "p2: J1 barely moves (RMS 0.6 N·m)"]
    assert _identify_summary({**d, "validation": []})[0] == ("Use dynid OLS, not physically consistent; dynid export writes dynid SDP, "
                                       "which is consistent.")
    consistent = {**d, "validation": [], "physically_consistent_verdict": {"dynid OLS": "yes", "dynid SDP": "yes"}}
    assert _identify_summary(consistent)[0] == (
        "Use dynid OLS, physically consistent; dynid export writes dynid SDP, the consistent estimate with a whole set of "
        "standard parameters (the main estimate's are base parameters alone).")
    assert _identify_summary({**consistent, "main_estimate": "dynid SDP"})[0] == "Use dynid SDP, physically consistent."


def test_a_dead_torque_channel_is_said_where_the_errors_say_over_all_joints():
    """A log with a joint whose torque reads a constant (the zoo's xArm7 dead-channel log, J4 at 0 N·m) had that
    joint left out of its errors while the terminal's and the report's summaries said "over all joints"; both now
    name it, and a resting log with a dead channel is not summed up with the others."""
    from dynid.report.html import identify_sections
    from dynid.report.summaries import ScoredLog, log_summaries

    lines = log_summaries([ScoredLog("dead", 0.482, (6, 6.55), False, 0.12, dead=(3,)),
                           ScoredLog("p1", 0.0, None, True), ScoredLog("p2", 0.0, None, True),
                           ScoredLog("p3", 0.0, None, True, dead=(0, 5))])
    assert lines[0] == ("dead: torque error 0.482 % over the joints but J4 (its torque reads a constant or the "
                        "drive's limit throughout: left out), worst J7 6.55 % (noise floor 0.12 %)")
    assert lines[1].startswith("p3: torque error 0 % over the joints but J1, J6 (their torques read a constant or the "
                               "drive's limit throughout: left out) "
                               "(at rest throughout")
    assert lines[2].startswith("p1, p2 (2 logs at rest throughout): torque error 0 % over all joints")
    log = {"name": "dead", "n_samples": 10, "relative_error_meaningful": [True, True], "dead_channels": [1],
           "metrics": {"dynid WLS": {"relative_error": [2.0, 0.0], "rmse": [1.0, 0.0], "correlation": [0.9, None],
                                     "global_relative_error": 2.0}}}
    d = {"robot": "r", "condition_number": 10.0, "n_rows": 100, "base_parameters": [], "main_estimate": "dynid WLS",
         "identification": {**log, "name": "identification", "dead_channels": []}, "validation": [log]}
    summary = next(s for s in identify_sections(d)[1] if s.title == "In short").texts
    assert ("dead: torque error 2 % over the joints but J2 (its torque reads a constant or the drive's limit throughout: "
            "left out), worst J1 2 %.") in summary


def test_results_json_names_the_dead_channels_of_a_log():
    import numpy as np

    from dynid.validation.torques import TorqueComparison

    measured = np.random.default_rng(0).normal(size=(50, 3))
    measured[:, 1] = 0.0
    t = np.arange(50) / 100.0
    c = TorqueComparison("dead", t, measured, {"A": measured + 0.01}, dead=(1,))
    assert c.to_dict()["dead_channels"] == [1]
    live = measured + 1.0
    assert "dead_channels" not in TorqueComparison("ok", t, live, {"A": live}).to_dict()


def test_the_publish_gate_says_which_joints_a_log_with_a_dead_channel_leaves_out():
    """The gate's sentence gave the zoo's TALOS-arm dead-channel log as "dead: 0.235 % against 3.32 %, over all
    joints" while J4's torque read 0 and was in neither figure."""
    import numpy as np

    from dynid.validation.diagnostics import nominal_gate
    from dynid.validation.torques import TorqueComparison

    rng = np.random.default_rng(1)
    measured = rng.normal(size=(80, 3)) + 2.0
    measured[:, 1] = 0.0
    t = np.arange(80) / 100.0
    c = TorqueComparison("dead", t, measured, {"A": measured + 0.01, "nominal": measured + 0.5}, dead=(1,))
    findings, _ = nominal_gate([c], "A", "nominal")
    assert "dead: " in findings[0].text and "% without J2 (a dead or saturated torque channel)" in findings[0].text
