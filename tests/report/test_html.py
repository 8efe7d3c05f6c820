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
    assert report.tables == 2 + n_logs and not report.external  # parameters, verdicts, one per log
    assert len(report.images) == len(list((tmp_path / "id").glob("*.png"))) == n_logs
    text = " ".join(report.text)
    assert "truth" in text and "dynid SDP" in text and "excitation band" in text
