"""Keys, labels and descriptions of the estimators (light: read while a config is checked, before the
estimators themselves are imported; :mod:`dynid.estimators.registry` builds them)."""

from __future__ import annotations

from ..exceptions import ConfigError

METHODS = ("ols", "wls", "irls", "lad", "sdp", "abc", "abc10", "de", "pso")
LABELS = {"ols": "OLS", "wls": "WLS", "irls": "IRLS", "lad": "LAD", "sdp": "SDP", "abc": "ABC", "abc10": "ABC×10",
          "de": "DE", "pso": "PSO"}
DESCRIPTIONS = {
    "ols": "ordinary least squares",
    "wls": "weighted least squares, one weight per joint",
    "irls": "iteratively reweighted least squares (Huber)",
    "lad": "least absolute deviations: exact minimum of eq. 9 in the search box (HiGHS)",
    "sdp": "physically consistent least squares (SDP, cvxpy + Clarabel), prior: nominal parameters × U(0.7, 1.3)",
    "abc": "artificial bee colony, the paper's budget",
    "abc10": "artificial bee colony, 10× the paper's iterations",
    "de": "differential evolution (SciPy), the budget of ABC×10",
    "pso": "particle swarm (constriction), the budget of ABC×10",
}
LEAST_SQUARES = ("ols", "wls")
"""The least-squares estimates that carry σ (``[estimation] method`` of ``dynid identify``)."""
BOX_SEARCHES = ("abc", "abc10", "de", "pso")
"""Methods that search the box for the minimum of eq. 9 and count objective evaluations."""
BOOTSTRAPPED = ("ols", "wls")
"""Methods cheap enough to refit on every bootstrap resample (IRLS reports Huber's sandwich covariance)."""


def parse_methods(text: str | tuple | list | None) -> tuple[str, ...]:
    """Method keys from ``"ols,abc"`` (or a sequence); ``None`` or ``"all"`` gives :data:`METHODS`.

    Raises
    ------
    ConfigError
        Unknown or repeated method.
    """
    if text is None or text == "all":
        return METHODS
    keys = [k.strip().lower() for k in (text.split(",") if isinstance(text, str) else text)]
    unknown = [k for k in keys if k not in METHODS]
    if unknown or not keys:
        raise ConfigError(f"methods: expected a comma-separated subset of {', '.join(METHODS)} (or all), got {text!r}", field="methods")
    if len(set(keys)) != len(keys):
        raise ConfigError(f"methods: each method once, got {text!r}", field="methods")
    return tuple(keys)
