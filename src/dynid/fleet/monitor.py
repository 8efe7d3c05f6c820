"""``dynid monitor``: a robot's friction and drive terms followed through its service life, and an alarm when one of
them changes (the field's indicator of gearbox wear).

The rigid-body part stays that of the last full identification (its results.json); each new log is prepared as the
identification prepared its own (the resolved filters carried over), its torques less the rigid-body prediction
leave, for each joint, what its friction and offset explain. On every window of ``window`` seconds, each joint's
friction terms are re-identified by least squares (their σ from the window's residual); recursive least squares
with forgetting (:mod:`dynid.estimators.recursive`) follows them sample by sample meanwhile. The first
``reference_windows`` windows set each term's reference (mean and spread: what the term does when nothing
changes, temperature and noise included; the spread taken at its upper 95 % confidence bound, since an
underestimated spread multiplies false alarms; windows that did not determine a term, such as a joint that kept one
direction, left out of its reference). From then on each window's estimate, standardised by the reference spread
and its own σ, feeds a two-sided CUSUM chart per term (:mod:`dynid.fleet.change_detection`) whose threshold
gives the whole family one false alarm per ``false_alarm_days`` days of logs on average. An alarm names the joint and the term, dates the
change (log and time), and says how large it is; the term's new level is then learned over the next
``reference_windows`` windows and its chart restarts from it, so a wear that goes on raises a new alarm each time it
has moved as much again.

The monitor follows a stream: :meth:`FrictionMonitor.feed` takes one prepared log (or chunk of one) at a time, and its
whole state is saved as data (:meth:`FrictionMonitor.state`, :func:`resumed_monitor`), so that ``dynid monitor`` run
every day on a growing folder reads only the logs it has not seen (``monitor-state.json`` in its output folder) and
gives what one run over every log would. The state is a JSON document of a fixed schema (numbers only, arrays as
little-endian float64 in base64, so that they come back bit for bit); it is checked, field by field, before any of it
is used, and nothing in it is ever executed: a results folder is something users pass around.
"""

from __future__ import annotations

import hashlib
import re
import time
import warnings
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path

import msgspec
import numpy as np

from .._util.reprs import short_repr
from ..estimators.pooled import own_term
from ..estimators.recursive import RecursiveLeastSquares
from ..exceptions import ConfigError, DataError
from ..friction import TERMS
from ..io.config.identification_config import dataset_for_file
from ..io.logs.datasets import load_recording
from ..preprocessing.strategies import carried_over
from .change_detection import Cusum, CusumAlarm, cusum_threshold

__all__ = ["MonitorSettings", "MonitorWindow", "DriftAlarm", "MonitorResult", "FrictionMonitor", "dated_logs",
           "monitor_logs", "determined", "STATE_FILE", "LEGACY_STATE_FILE", "monitor_fingerprint", "resumed_monitor",
           "legacy_state_refusal"]

STATE_FILE = "monitor-state.json"
"""The monitor's state in ``dynid monitor``'s output folder: the next run goes on from it."""
LEGACY_STATE_FILE = "monitor-state.pkl"
"""The state's name in development versions of 0.2.0 (a pickle): never read, since unpickling a file can run code."""
_STATE_FORMAT = "dynid-monitor-state"
_STATE_VERSION = 2

_DATE = re.compile(r"(\d{4})-(\d{2})-(\d{2})(?:[T_ ](\d{2})[-:](\d{2})(?:[-:](\d{2}))?)?")


@dataclass(frozen=True)
class MonitorSettings:
    """How a monitor windows, references and alarms.

    Attributes
    ----------
    window : float [s]
        Log time per window.
    reference_windows : int
        Windows that set each term's reference (the first of the monitored logs).
    false_alarm_days : float [days]
        The family of charts raises a false alarm once per this many days of logs, on average.
    forgetting_seconds : float [s]
        Memory of the recursive estimate (its forgetting factor is ``1 - 1 / (rows in this time)``).
    shift : float
        The smallest change, in reference spreads, the charts are tuned to (their reference value k is half of it).
        Two spreads: a reference mean estimated from a few dozen windows is itself off by a few tenths of a spread,
        which charts tuned to smaller shifts would accumulate into false alarms.
    """

    window: float = 10.0
    reference_windows: int = 60
    false_alarm_days: float = 30.0
    forgetting_seconds: float = 60.0
    shift: float = 2.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.window) and self.window > 0):
            raise ConfigError(f"window must be a positive number of seconds, got {self.window}", field="window")
        if self.reference_windows < 3:
            raise ConfigError(f"reference_windows must be at least 3, got {self.reference_windows}", field="reference_windows")
        if not (np.isfinite(self.false_alarm_days) and self.false_alarm_days > 0):
            raise ConfigError(f"false_alarm_days must be positive, got {self.false_alarm_days}", field="false_alarm_days")


@short_repr
@dataclass(frozen=True)
class MonitorWindow:
    """One window's re-identified terms.

    Attributes
    ----------
    log : str
    start, end : float [s]
        In the log.
    theta, std : (n_terms,) arrays
        The terms (NaN where the joint did not move enough) and their σ.
    tracked : (n_terms,) array
        The recursive estimate at the window's end.
    """

    log: str
    start: float
    end: float
    theta: np.ndarray
    std: np.ndarray
    tracked: np.ndarray


@dataclass(frozen=True)
class DriftAlarm:
    """A term that changed.

    Attributes
    ----------
    joint : int
        1-based.
    term : str
        Its base parameter name (``fv3``).
    since_log, since : str, float [s]
        Where the change starts: the log and the time in it.
    detected_log, detected : str, float [s]
        Where the alarm was raised.
    reference : float
        The term's reference value.
    value : float
        Its mean since the change.
    delay : float [s]
        Log time from the change to the alarm.
    """

    joint: int
    term: str
    since_log: str
    since: float
    detected_log: str
    detected: float
    reference: float
    value: float
    delay: float

    @property
    def change(self) -> float:
        """Relative change [%]."""
        return 100 * (self.value - self.reference) / abs(self.reference) if self.reference else float("inf")

    def __str__(self) -> str:
        term = TERMS.get(re.sub(r"\d+$", "", self.term))
        kind = term.description.split(",")[0] if term is not None else self.term
        verb = "rose" if self.value > self.reference else "fell"
        return (f"joint {self.joint}: {kind} ({self.term}) {verb} {abs(self.change):.3g} % ({self.reference:.4g} -> "
                f"{self.value:.4g}) since {self.since_log} at {self.since:.0f} s; alarm in {self.detected_log} at "
                f"{self.detected:.0f} s, {self.delay:.0f} s of logs later")

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"joint": self.joint, "term": self.term, "since_log": self.since_log, "since_s": self.since,
                "detected_log": self.detected_log, "detected_s": self.detected, "reference": self.reference,
                "value": self.value, "change_percent": self.change, "delay_s": self.delay, "message": str(self)}


@short_repr
@dataclass(frozen=True)
class MonitorResult:
    """A monitored service life.

    Attributes
    ----------
    terms : tuple of str
        The monitored terms (base parameter names).
    joints : tuple of int
        Each term's joint (1-based).
    windows : tuple of MonitorWindow
    reference_mean, reference_std : (n_terms,) arrays
    threshold : float
        The CUSUM decision interval h.
    alarms : tuple of DriftAlarm
    settings : MonitorSettings
    logs : tuple of str
        Every log monitored so far, oldest first.
    state : bytes or None
        The monitor's state to go on from (:meth:`FrictionMonitor.state`), when the run was asked to keep it.
    resumed : int
        Logs of an earlier run this one went on from (0: a new monitor).
    deferred : tuple of str
        Logs still being written, left for the next run (one line each, naming them).
    """

    terms: tuple[str, ...]
    joints: tuple[int, ...]
    windows: tuple[MonitorWindow, ...]
    reference_mean: np.ndarray
    reference_std: np.ndarray
    threshold: float
    alarms: tuple[DriftAlarm, ...]
    settings: MonitorSettings
    logs: tuple[str, ...] = ()
    state: bytes | None = field(default=None, repr=False, compare=False)
    resumed: int = 0
    deferred: tuple[str, ...] = ()

    @property
    def latest(self) -> np.ndarray:
        """(n_terms,) Each term's level now (:func:`recent_level`: the window estimates of the last
        ``settings.forgetting_seconds`` of log); NaN before the first window."""
        if not self.windows:
            return np.full(len(self.terms), np.nan)
        return recent_level(self.windows, self.settings.forgetting_seconds)

    def changes(self) -> dict[str, float]:
        """Each term that alarmed, with how far its level now is from its reference [%] (every alarm in between
        counted in).

        Returns
        -------
        dict
            term -> relative change [%], in the order of the terms.
        """
        alarmed = {a.term for a in self.alarms}
        return {t: 100 * float(x - m) / abs(float(m)) if m else float("inf")
                for t, m, x in zip(self.terms, self.reference_mean, self.latest) if t in alarmed}

    def to_dict(self) -> dict:
        """JSON-ready: the alarms, the reference, every window's terms.

        Returns
        -------
        dict
        """
        return {"kind": "monitor", "terms": list(self.terms), "alarms": [a.to_dict() for a in self.alarms],
                "reference": {t: {"mean": float(m), "std": float(s)} for t, m, s in
                              zip(self.terms, self.reference_mean, self.reference_std)},
                "latest": {t: float(x) for t, x in zip(self.terms, self.latest)},
                "changed_percent": self.changes(),
                "cusum_threshold": self.threshold,
                "settings": {"window_s": self.settings.window, "reference_windows": self.settings.reference_windows,
                             "shift": self.settings.shift,
                             "false_alarm_days": self.settings.false_alarm_days,
                             "forgetting_seconds": self.settings.forgetting_seconds},
                "logs": list(self.logs),
                "windows": [{"log": w.log, "start_s": w.start, "end_s": w.end,
                             "terms": dict(zip(self.terms, np.where(np.isfinite(w.theta), w.theta, np.nan).tolist())),
                             "std": dict(zip(self.terms, w.std.tolist())),
                             "tracked": dict(zip(self.terms, w.tracked.tolist()))} for w in self.windows]}


UNDETERMINED = 3.0
"""A window's estimate of a term whose σ exceeds this many times the term's median σ over the reference windows did
not determine it."""


def determined(sigmas: np.ndarray) -> np.ndarray:
    """Which windows determine each term: σ at most :data:`UNDETERMINED` times the term's median σ over the windows.

    Parameters
    ----------
    sigmas : (n_windows, n_terms) array
        Each window's σ of each term (inf where not estimated).

    Returns
    -------
    (n_windows, n_terms) bool ndarray
    """
    finite = np.where(np.isfinite(sigmas), sigmas, np.nan)
    with np.errstate(all="ignore"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.asarray(sigmas <= UNDETERMINED * np.nanmedian(finite, axis=0), dtype=bool)


def reference_level(windows) -> tuple[np.ndarray, np.ndarray]:
    """Each term's reference mean and spread over the reference windows.

    A window that did not determine a term (:func:`determined`: a joint that kept one direction, whose Coulomb friction
    and offset are then one column) is left out of that term's reference. The spread is itself estimated from the
    windows: its upper 95 % confidence bound, at least the windows' median σ, widened by the mean's own uncertainty,
    so that the charts' false-alarm rate holds (a spread 15 % low would make false alarms some 40 times as frequent).

    Parameters
    ----------
    windows : sequence of MonitorWindow
        The reference windows.

    Returns
    -------
    mean, spread : (n_terms,) arrays
    """
    from scipy.stats import chi2

    ref = len(windows)
    values = np.array([w.theta for w in windows])
    sigmas = np.array([w.std for w in windows])
    values = np.where(determined(sigmas), values, np.nan)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(values, axis=0)
        upper = np.sqrt((ref - 1) / chi2.ppf(0.05, ref - 1))
        spread = np.fmax(np.nanstd(values, axis=0, ddof=1) * upper,
                         np.nanmedian(np.where(np.isfinite(sigmas), sigmas, np.nan), axis=0)) * np.sqrt(1 + 1 / ref)
    return mean, spread


def recent_level(windows, seconds: float) -> np.ndarray:
    """Each term's level now: the mean of the window estimates in the last ``seconds`` of log (at least the last
    window), the windows that did not determine a term (:func:`determined`, over every window) left out; NaN where
    none did. What the monitor's figure shows at its right end.

    Parameters
    ----------
    windows : sequence of MonitorWindow
        At least one.
    seconds : float [s]

    Returns
    -------
    (n_terms,) array
    """
    values = np.array([w.theta for w in windows])
    values = np.where(determined(np.array([w.std for w in windows])), values, np.nan)
    elapsed = np.cumsum([w.end - w.start for w in windows][::-1])
    last = int(np.searchsorted(elapsed, seconds - 1e-9)) + 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(values[-last:], axis=0)


def dated_logs(folder: str | Path, pattern: str = "*.csv") -> list[Path]:
    """The logs of a folder in time order: by the date and time in their names (``2026-01-15T08-30.csv``), else by name.

    Parameters
    ----------
    folder : path
    pattern : str

    Returns
    -------
    list of Path

    Raises
    ------
    ConfigError
        Not a folder, or no log in it.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ConfigError(f"{folder}: not a folder of logs", field="logs")
    files = [p for p in folder.glob(pattern) if p.is_file()]
    if not files:
        raise ConfigError(f"{folder}: no log matching {pattern}", field="logs")

    def key(p: Path):
        m = _DATE.search(p.name)
        return (0, tuple(int(g or 0) for g in m.groups()), p.name) if m else (1, (), p.name)

    return sorted(files, key=key)


class FrictionMonitor:
    """The monitor's state through a stream of prepared logs (module docstring).

    Parameters
    ----------
    robot : Robot
        As identified (its friction terms and Coulomb smoothing).
    base : BaseParameters
    params : (n_base,) array
        The last full identification's base parameters.
    settings : MonitorSettings

    Raises
    ------
    DataError
        Base parameters without per-joint friction or offset terms.
    """

    def __init__(self, robot, base, params, settings: MonitorSettings = MonitorSettings()):
        self.robot, self.base, self.settings = robot, base, settings
        self.params = np.asarray(params, dtype=float)
        names = list(base.names)
        self.columns: list[list[int]] = []
        terms, joints = [], []
        for j in range(robot.n_dof):
            cols = [i for i, nm in enumerate(names) if own_term(nm) and re.fullmatch(rf"[a-z]+{j + 1}", nm)]
            self.columns.append(cols)
            terms += [names[i] for i in cols]
            joints += [j + 1] * len(cols)
        if not terms:
            raise DataError("the identification has no per-joint friction or offset terms to monitor")
        self.terms, self.joints = tuple(terms), tuple(joints)
        self.q = max(len(c) for c in self.columns)
        rigid = np.ones(len(names), dtype=bool)
        rigid[[i for c in self.columns for i in c]] = False
        self.rigid = rigid
        theta0 = np.zeros((robot.n_dof, self.q))
        for j, cols in enumerate(self.columns):
            theta0[j, :len(cols)] = self.params[cols]
        self.rls: RecursiveLeastSquares | None = None
        self.theta0 = theta0
        self.windows: list[MonitorWindow] = []
        self.alarms: list[DriftAlarm] = []
        self.cusum: Cusum | None = None
        self.mean, self.std = np.full(len(terms), np.nan), np.full(len(terms), np.nan)
        self.threshold = float("nan")
        self.elapsed = 0.0  # log time seen [s]
        self.relearn: dict[int, list] = {}
        self.window_times: list[tuple[str, float, float]] = []  # (log, start, end) of each window, for dating alarms
        self.logs: list[str] = []
        self.sizes: dict[str, int] = {}  # each log's size in bytes when it was read

    def _flat(self, theta: np.ndarray) -> np.ndarray:
        return np.concatenate([theta[j, :len(c)] for j, c in enumerate(self.columns)])

    def feed(self, data, name: str) -> list[DriftAlarm]:
        """Take in one prepared log.

        Parameters
        ----------
        data : PreparedData
            Prepared with the identification's resolved settings.
        name : str
            The log's name (alarms name it).

        Returns
        -------
        list of DriftAlarm
            The alarms this log raised.
        """
        from ..preprocessing.preparation import base_chunks

        n, q = self.robot.n_dof, self.q
        self.logs.append(name)
        t_parts, phi_parts, r_parts, keep_parts = [], [], [], []
        for index, y, tau, keep in base_chunks(self.robot, self.base, data):
            residual = tau - y[:, :, self.rigid] @ self.params[self.rigid]
            phi = np.zeros((y.shape[0], n, q))
            for j, cols in enumerate(self.columns):
                phi[:, j, :len(cols)] = y[:, j, cols]
            t_parts.append(np.asarray(data.t)[index])
            phi_parts.append(phi)
            r_parts.append(residual)
            keep_parts.append(keep)
        if not t_parts:
            return []
        t, phi, r, keep = (np.concatenate(x) for x in (t_parts, phi_parts, r_parts, keep_parts))
        if self.rls is None:
            rows_per_second = len(t) / max(float(t[-1] - t[0]), 1e-9)
            lam = 1.0 - 1.0 / max(self.settings.forgetting_seconds * rows_per_second, 2.0)
            self.rls = RecursiveLeastSquares(self.theta0, 1e2, lam)
        new: list[DriftAlarm] = []
        edges = np.arange(t[0], t[-1] + 1e-9, self.settings.window)
        for a, b in zip(edges[:-1], edges[1:]):
            rows = (t >= a) & (t < b)
            if rows.sum() < 4 * q:
                continue
            tracked = self.rls.update(phi[rows], r[rows], keep[rows])
            theta, std = self._window_fit(phi[rows], r[rows], keep[rows])
            self.windows.append(MonitorWindow(name, float(a), float(b), theta, std, self._flat(tracked)))
            self.window_times.append((name, float(a), float(b)))
            new += self._chart()
        self.alarms += new
        return new

    def _window_fit(self, phi, r, keep) -> tuple[np.ndarray, np.ndarray]:
        """Each joint's terms by least squares on the window, with σ; NaN where the joint did not move enough."""
        theta, std = [], []
        for j, cols in enumerate(self.columns):
            k = len(cols)
            a, y = phi[keep[:, j], j, :k], r[keep[:, j], j]
            if a.shape[0] < 4 * k or np.linalg.cond(a) > 1e6:
                theta.append(np.full(k, np.nan))
                std.append(np.full(k, np.inf))
                continue
            sol, *_ = np.linalg.lstsq(a, y, rcond=None)
            dof = max(a.shape[0] - k, 1)
            s2 = float(np.sum((y - a @ sol) ** 2)) / dof
            theta.append(sol)
            std.append(np.sqrt(np.maximum(np.diag(np.linalg.inv(a.T @ a)) * s2, 0.0)))
        return np.concatenate(theta), np.concatenate(std)

    def _chart(self) -> list[DriftAlarm]:
        count = len(self.windows)
        ref = self.settings.reference_windows
        if count < ref:
            return []
        if count == ref:
            self.mean, self.std = reference_level(self.windows)
            per_day = 86400.0 / self.settings.window
            k = self.settings.shift / 2
            self.threshold = cusum_threshold(self.settings.false_alarm_days * per_day, 2 * len(self.terms), k)
            self.cusum = Cusum(len(self.terms), self.threshold, k)
            return []
        assert self.cusum is not None
        w = self.windows[-1]
        # the window's own σ enters, so that a term it determines poorly cannot make a large step of its chart
        z = (w.theta - self.mean) / np.sqrt(self.std**2 + np.where(np.isfinite(w.std), w.std, np.inf) ** 2)
        for c, seen in list(self.relearn.items()):  # a term that alarmed: its new level learned before its chart restarts
            seen.append(w.theta[c])
            z[c] = np.nan
            if len(seen) >= self.settings.reference_windows:
                self.mean[c] = float(np.nanmean(seen))
                del self.relearn[c]
        out = []
        for alarm in self.cusum.update(z):
            start = ref + alarm.start  # windows before the chart started are the reference
            since_log, since, _ = self.window_times[start]
            c = alarm.channel
            values = np.array([x.theta[c] for x in self.windows[start:]])
            elapsed = sum(e - s for _, s, e in self.window_times[start:])
            out.append(DriftAlarm(self.joints[c], self.terms[c], since_log, since, w.log, w.end, float(self.mean[c]),
                                  float(np.nanmean(values)), float(elapsed)))
            self.relearn[c] = []  # the change is said: the chart follows the term's new level once it is learned
        return out

    def state(self, fingerprint: str) -> bytes:
        """The whole state, to go on from later (:func:`resumed_monitor`).

        Parameters
        ----------
        fingerprint : str
            What the state is valid for (:func:`monitor_fingerprint`).

        Returns
        -------
        bytes
            A JSON document of the schema :class:`_State` (data only: reading it back runs no code).
        """
        cusum = None
        if self.cusum is not None:
            c = self.cusum
            cusum = _CusumState(_num(c.h), _num(c.k), _Array.of(c.up), _Array.of(c.down), c.start_up.tolist(), c.start_down.tolist(),
                                c.count, _Array.of(np.array(c.history).reshape(len(c.history), len(self.terms))),
                                [_CusumAlarmState(a.channel, a.index, a.start, a.direction, _num(a.shift)) for a in c.alarms])
        rls = None if self.rls is None else _RlsState(_Array.of(self.rls.theta), _Array.of(self.rls.p),
                                                      _num(self.rls.forgetting))
        state = _State(
            _STATE_FORMAT, _STATE_VERSION, fingerprint, list(self.terms), rls,
            [_WindowState(w.log, _num(w.start), _num(w.end), _Array.of(w.theta), _Array.of(w.std), _Array.of(w.tracked))
             for w in self.windows],
            [_AlarmState(a.joint, a.term, a.since_log, _num(a.since), a.detected_log, _num(a.detected),
                         _num(a.reference), _num(a.value), _num(a.delay)) for a in self.alarms],
            cusum, _Array.of(self.mean), _Array.of(self.std), _num(self.threshold), _num(self.elapsed),
            {str(c): _Array.of(np.array(v, dtype=float)) for c, v in self.relearn.items()},
            [[log, _num(a), _num(b)] for log, a, b in self.window_times], list(self.logs), dict(self.sizes))
        return msgspec.json.encode(state)

    def _restore(self, state: _State, where: str) -> None:
        """Take the saved state's values, each checked against this monitor's terms (:func:`resumed_monitor`)."""
        n_terms, (n, q) = len(self.terms), self.theta0.shape

        def bad(what: str) -> DataError:
            return DataError(f"{where}: not a monitor state dynid can read ({what}); remove it or give --restart")

        def terms_array(a: _Array, what: str) -> np.ndarray:
            return a.array((n_terms,), bad(f"{what}: expected {n_terms} values"))

        if tuple(state.terms) != self.terms:
            raise bad(f"terms {state.terms} are not the identification's {list(self.terms)}")
        if state.rls is not None:
            self.rls = RecursiveLeastSquares(state.rls.theta.array((n, q), bad("rls.theta: wrong shape")),
                                             state.rls.p.array((n, q, q), bad("rls.p: wrong shape")),
                                             _forgetting(_value(state.rls.forgetting, bad), bad))
        self.windows = [MonitorWindow(w.log, _value(w.start, bad), _value(w.end, bad), terms_array(w.theta, "window theta"),
                                      terms_array(w.std, "window std"), terms_array(w.tracked, "window tracked"))
                        for w in state.windows]
        self.alarms = [DriftAlarm(a.joint, a.term, a.since_log, _value(a.since, bad), a.detected_log,
                                  _value(a.detected, bad), _value(a.reference, bad), _value(a.value, bad),
                                  _value(a.delay, bad)) for a in state.alarms]
        self.mean, self.std = terms_array(state.mean, "mean"), terms_array(state.std, "std")
        self.threshold, self.elapsed = _value(state.threshold, bad), _value(state.elapsed, bad)
        self.relearn = {}
        for key, values in state.relearn.items():
            if not (key.isdigit() and int(key) < n_terms):
                raise bad(f"relearn: {key!r} is no term's index")
            self.relearn[int(key)] = list(values.array((len(values.data) // 8,), bad("relearn: wrong size")))
        if any(len(w) != 3 or not isinstance(w[0], str) for w in state.window_times) \
                or len(state.window_times) != len(self.windows):
            raise bad("window_times: expected one [log, start, end] per window")
        self.window_times = [(str(w[0]), _value(w[1], bad), _value(w[2], bad)) for w in state.window_times]
        self.logs = list(state.logs)
        if any(v < 0 for v in state.sizes.values()):
            raise bad("sizes: expected sizes in bytes")
        self.sizes = dict(state.sizes)
        self.cusum = None
        if state.cusum is not None:
            c = state.cusum
            count = c.count
            if count < 0 or len(c.start_up) != n_terms or len(c.start_down) != n_terms:
                raise bad("cusum: wrong sizes")
            if any(not 0 <= a.channel < n_terms for a in c.alarms):
                raise bad("cusum alarms: a channel outside the terms")
            self.cusum = Cusum(n_terms, _value(c.h, bad), _value(c.k, bad))
            self.cusum.up, self.cusum.down = terms_array(c.up, "cusum up"), terms_array(c.down, "cusum down")
            self.cusum.start_up = np.array(c.start_up, dtype=int)
            self.cusum.start_down = np.array(c.start_down, dtype=int)
            self.cusum.count = count
            self.cusum.history = list(c.history.array((count, n_terms), bad("cusum history: wrong shape")))
            self.cusum.alarms = [CusumAlarm(a.channel, a.index, a.start, a.direction, _value(a.shift, bad))
                                 for a in c.alarms]

    def result(self) -> MonitorResult:
        """The monitored life so far.

        Returns
        -------
        MonitorResult
        """
        ref = self.settings.reference_windows
        # the reference as first learned: a term that alarmed follows its new level in self.mean, and a table, figure
        # or change read against that level would hide how far the term has gone in all
        mean = reference_level(self.windows[:ref])[0] if len(self.windows) >= ref else self.mean
        return MonitorResult(self.terms, self.joints, tuple(self.windows), mean, self.std, self.threshold,
                             tuple(self.alarms), self.settings, tuple(self.logs))


def monitor_fingerprint(results: str | Path, settings: MonitorSettings) -> str:
    """What a monitor's state is valid for: the identification it started from (its results.json's bytes) and its
    settings.

    Parameters
    ----------
    results : str or Path
        The results.json of the last full identification.
    settings : MonitorSettings

    Returns
    -------
    str
        A SHA-256 hex digest.
    """
    digest = hashlib.sha256(Path(results).read_bytes())
    digest.update(repr(settings).encode())
    return digest.hexdigest()


def resumed_monitor(path: str | Path, fingerprint: str, model,
                    settings: MonitorSettings = MonitorSettings()) -> FrictionMonitor:
    """A monitor's saved state (:meth:`FrictionMonitor.state`), to feed it the logs it has not seen.

    The file is read as data of a fixed schema and checked field by field (types, shapes, the identification's terms)
    before any of it is used; nothing in it is executed.

    Parameters
    ----------
    path : str or Path
        ``monitor-state.json``.
    fingerprint : str
        :func:`monitor_fingerprint` of this run: the state must have been made from the same identification and
        settings.
    model : IdentifiedModel
        The identification the state was made from (:func:`dynid.load_results`).
    settings : MonitorSettings

    Returns
    -------
    FrictionMonitor

    Raises
    ------
    DataError
        A file that is no monitor state of this dynid, or one made from another identification or other settings.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
        header = msgspec.json.decode(raw, type=_Header)
        if header.format != _STATE_FORMAT:
            raise ValueError(f"format {header.format!r}")
    except (OSError, msgspec.DecodeError, ValueError) as exc:
        raise DataError(f"{path}: not a monitor state dynid can read ({_first_line(exc)}); remove it or give "
                        "--restart") from None
    if header.version != _STATE_VERSION:
        raise DataError(f"{path}: a monitor state of another dynid version (schema {header.version}, this dynid "
                        f"reads {_STATE_VERSION}); give --restart to start over")
    if header.fingerprint != fingerprint:
        raise DataError(f"{path}: made from another identification or with other monitor settings (--window, "
                        "--reference-windows, --false-alarm-days); give --restart to start over, or another --out")
    try:
        state = msgspec.json.decode(raw, type=_State)
    except msgspec.DecodeError as exc:
        raise DataError(f"{path}: not a monitor state dynid can read ({_first_line(exc)}); remove it or give "
                        "--restart") from None
    monitor = FrictionMonitor(model.robot, model.base, model.params(), settings)
    monitor._restore(state, str(path))
    return monitor


def legacy_state_refusal(folder: str | Path) -> str | None:
    """The one line that refuses an output folder holding only a pickled state of a development version, or None.

    Parameters
    ----------
    folder : str or Path
        ``dynid monitor``'s ``--out``.

    Returns
    -------
    str or None
    """
    folder = Path(folder)
    if (folder / LEGACY_STATE_FILE).exists() and not (folder / STATE_FILE).exists():
        return (f"{folder / LEGACY_STATE_FILE}: a monitor state of an earlier dynid, a pickle, which dynid no longer "
                "reads (reading one can run code); give --restart to monitor every log anew (it writes "
                f"{STATE_FILE}), then delete the .pkl")
    return None


_NON_FINITE = {"nan": float("nan"), "inf": float("inf"), "-inf": float("-inf")}


def _num(x: float) -> float | str:
    """A number for the state: finite as it is, non-finite as ``"nan"``, ``"inf"`` or ``"-inf"`` (JSON has none)."""
    x = float(x)
    return x if np.isfinite(x) else repr(x)


def _value(x: float | str, bad) -> float:
    if isinstance(x, str):
        if x not in _NON_FINITE:
            raise bad(f"{x!r} is no number")
        return _NON_FINITE[x]
    return float(x)


def _first_line(exc: BaseException) -> str:
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def _forgetting(value: float, bad) -> float:
    if not 0 < value <= 1:
        raise bad("rls.forgetting: expected a factor in (0, 1]")
    return value


class _Array(msgspec.Struct, forbid_unknown_fields=True):
    """An array of float64 in the state: its shape and its little-endian bytes (base64 in JSON), exact."""

    shape: list[int]
    data: bytes

    @classmethod
    def of(cls, a) -> _Array:
        a = np.ascontiguousarray(a, dtype="<f8")
        return cls(list(a.shape), a.tobytes())

    def array(self, shape: tuple[int, ...], error: Exception) -> np.ndarray:
        if tuple(self.shape) != tuple(shape) or len(self.data) != 8 * int(np.prod(shape, dtype=np.int64)):
            raise error
        return np.frombuffer(self.data, dtype="<f8").reshape(shape).astype(float)


class _Header(msgspec.Struct):
    format: str
    version: int
    fingerprint: str


class _RlsState(msgspec.Struct, forbid_unknown_fields=True):
    theta: _Array
    p: _Array
    forgetting: float | str


class _WindowState(msgspec.Struct, forbid_unknown_fields=True):
    log: str
    start: float | str
    end: float | str
    theta: _Array
    std: _Array
    tracked: _Array


class _AlarmState(msgspec.Struct, forbid_unknown_fields=True):
    joint: int
    term: str
    since_log: str
    since: float | str
    detected_log: str
    detected: float | str
    reference: float | str
    value: float | str
    delay: float | str


class _CusumAlarmState(msgspec.Struct, forbid_unknown_fields=True):
    channel: int
    index: int
    start: int
    direction: int
    shift: float | str


class _CusumState(msgspec.Struct, forbid_unknown_fields=True):
    h: float | str
    k: float | str
    up: _Array
    down: _Array
    start_up: list[int]
    start_down: list[int]
    count: int
    history: _Array
    alarms: list[_CusumAlarmState]


class _State(msgspec.Struct, forbid_unknown_fields=True):
    """The schema of ``monitor-state.json`` (version 2)."""

    format: str
    version: int
    fingerprint: str
    terms: list[str]
    rls: _RlsState | None
    windows: list[_WindowState]
    alarms: list[_AlarmState]
    cusum: _CusumState | None
    mean: _Array
    std: _Array
    threshold: float | str
    elapsed: float | str
    relearn: dict[str, _Array]
    window_times: list[list[str | float]]
    logs: list[str]
    sizes: dict[str, int] = {}


def monitor_logs(config, model, logs: Iterable[Path], settings: MonitorSettings = MonitorSettings(),
                 progress=None, resume: FrictionMonitor | None = None, fingerprint: str | None = None) -> MonitorResult:
    """Monitor a robot through its logs, oldest first.

    Parameters
    ----------
    config : IdentificationConfig
        The robot's identify config: its identification dataset's column map reads the logs.
    model : IdentifiedModel
        The last full identification (:func:`dynid.load_results`).
    logs : iterable of Path
        In time order (:func:`dated_logs`).
    settings : MonitorSettings
    progress : callable, optional
        ``progress(step, done, total)``.
    resume : FrictionMonitor, optional
        An earlier run's monitor (:func:`resumed_monitor`): the logs it has seen are skipped, the others fed to it.
    fingerprint : str, optional
        Keep the state (:attr:`MonitorResult.state`) for the next run, valid for this (:func:`monitor_fingerprint`).

    Returns
    -------
    MonitorResult

    Raises
    ------
    DataError
        A log that cannot be read, too few windows for the reference, or (resuming) a new log that sorts before the
        last one the monitor saw.
    """
    from ..preprocessing.preparation import prepare

    logs = list(logs)
    monitor = resume if resume is not None else FrictionMonitor(model.robot, model.base, model.params(), settings)
    resumed = len(monitor.logs)
    if resume is not None:
        seen = set(monitor.logs)
        last = max((i for i, p in enumerate(logs) if p.name in seen), default=-1)
        early = [p.name for p in logs[:last] if p.name not in seen]
        if early:
            raise DataError(f"{early[0]}: a new log that sorts before {logs[last].name}, the last one the monitor saw "
                            "(it follows time); give --restart to monitor every log again")
        grown = [p for p in logs if p.name in monitor.sizes and p.stat().st_size != monitor.sizes[p.name]]
        if grown:
            p = grown[0]
            raise DataError(f"{p.name}: changed since the monitor read it ({monitor.sizes[p.name]} -> {p.stat().st_size} "
                            "bytes: was it still being written?); give --restart to monitor every log again")
        logs = [p for p in logs if p.name not in seen]
    logs, deferred = _complete(logs)
    prep = carried_over(model.preprocessing, config.preprocessing)
    for i, path in enumerate(logs):
        if progress is not None:
            progress(f"log {path.name}", i, len(logs))
        size = path.stat().st_size
        recording = load_recording(dataset_for_file(config, path), model.robot)
        monitor.feed(prepare(recording, prep, strict=False), path.name)
        monitor.sizes[path.name] = size
    if len(monitor.windows) <= settings.reference_windows:
        left = f"; {deferred[0]}" if deferred else ""
        raise DataError(f"{len(monitor.windows)} windows of {settings.window:g} s in the logs: the reference needs "
                        f"{settings.reference_windows} and monitoring more (give more logs, or --reference-windows){left}")
    return replace(monitor.result(), state=None if fingerprint is None else monitor.state(fingerprint), resumed=resumed,
                   deferred=deferred)


WRITING_AGE = 300.0
"""[s] The newest log, its last line without a newline, is taken as still being written where it changed this
recently. A log that a later one follows, or that has not changed for longer, is complete: a logger writes the newest,
and a finished log may just end without a newline (the UR10e's RTDE logs of Mamedov & Mikhel 2020 do: the first of
them read as "still being written" left every log for the next run, and the monitor said "0 windows")."""


def _complete(logs: list[Path], now: float | None = None) -> tuple[list[Path], tuple[str, ...]]:
    """The logs a run may read, in order, and the line that names the one left for the next run: the newest where its
    last line is unfinished (no newline at its end, or empty) and it changed within :data:`WRITING_AGE` (a logger still
    writing it).

    Parameters
    ----------
    logs : list of Path
        In time order.
    now : float, optional
        The time [s since the epoch] the age is measured at (default: now).

    Returns
    -------
    logs : list of Path
    deferred : tuple of str
        The line naming the log left, or nothing.
    """
    if not logs:
        return logs, ()
    path = logs[-1]
    stat = path.stat()
    with open(path, "rb") as fh:
        if stat.st_size:
            fh.seek(-1, 2)
        unfinished = stat.st_size == 0 or fh.read(1) != b"\n"
    if unfinished and (time.time() if now is None else now) - stat.st_mtime < WRITING_AGE:
        return logs[:-1], (f"{path.name}: still being written (its last line is unfinished): left for the next run",)
    return logs, ()
