"""Output folders and figure files shared by the reports (every file written atomically)."""

from __future__ import annotations

import contextlib
import functools
import inspect
import io
import json
import os
import shutil
import socket
import tempfile
import time
from pathlib import Path

from .. import __version__
from ..exceptions import ConfigError
from ..io import atomic_write_bytes, atomic_write_text, write_json
from ..runtime.processes import can_fork, pipe, start_child

MANIFEST = ".dynid-manifest.json"
"""Written last into an output folder: the files of the run that is there, whole."""


def check_output_folder(out: str | Path, writes: tuple[str, ...] = ()) -> Path:
    """Refuse, before any computation, an output folder that is a file or a folder that cannot be written, or that
    holds a file of the user's where the run writes one (:func:`foreign_files`).

    Parameters
    ----------
    out : str or Path
    writes : tuple of str
        Names of files the run will write there (those known before it runs).

    Returns
    -------
    Path
        ``out`` as a path.

    Raises
    ------
    ConfigError
        Names the path and the reason.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"out {out}: exists and is not a folder", field="out")
    parent = out if out.exists() else next((p for p in out.absolute().parents if p.exists()), Path("/"))
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigError(f"out {out}: {parent} is not writable", field="out")
    theirs = foreign_files(out, writes) if out.is_dir() and not _killed_in(out) else []
    if theirs:
        raise ConfigError(_foreign_message(theirs[0], out), field="out")
    return out


def foreign_files(out: Path, names) -> list[Path]:
    """The files of ``out`` named ``names`` that no earlier run into it wrote (not in its :data:`MANIFEST`): the
    user's own, which a run never replaces (unless a run was killed there, its staging folder left behind: its files
    are listed nowhere, and the callers let the next run replace them).

    Parameters
    ----------
    out : Path
        An existing folder.
    names : iterable of str

    Returns
    -------
    list of Path
    """
    previous = _manifest_files(out)
    return [out / n for n in names if ((out / n).exists() or (out / n).is_symlink()) and n not in previous]


def _killed_in(out: Path) -> bool:
    """A run was killed in ``out`` (its staging folder left behind): its files, listed nowhere, may be replaced."""
    return any(out.glob(_STAGING + "*"))


def _foreign_message(path: Path, out: Path) -> str:
    return (f"{path}: a file where this run writes one, which no earlier run into {out} wrote (its {MANIFEST} does not "
            "list it): move it, or give another output folder")


def staged(save):
    """Decorator that writes a command's files through a staging folder.

    For ``save(result, out, ...) -> paths``: the files are written into a hidden staging folder inside ``out``, then
    moved into ``out`` one by one; the files of an earlier run there that this one does not write again are removed,
    and the manifest (:data:`MANIFEST`) is written last. A file of the same name as one this run writes that no earlier
    run wrote (not in the manifest: the user's own) is refused before anything moves, unless a run was killed there
    (its staging folder left behind: its files are listed nowhere). An error or a Ctrl-C while saving leaves ``out`` as it was
    (the staging folder is removed). The old manifest is removed before the first file moves, so a folder killed while
    files move (SIGKILL, power loss) has no manifest: files without a manifest are an incomplete run. Staging folders
    such a kill leaves behind are removed by the next run into the same folder once they are an hour old.

    Parameters
    ----------
    save : callable
        ``save(result, out, ...)`` returning the paths written.

    Returns
    -------
    callable
        The same signature, ``out`` a folder that is created if needed; its docstring gains the sections every
        staged writer shares (:data:`_STAGED_SECTIONS`: what it returns and raises).
    """

    @functools.wraps(save)
    def wrapper(result, out, *args, **kwargs):
        out = output_folder(out)
        interrupted = _killed_in(out)  # before the stale staging folders go
        _remove_stale_staging(out)
        stage = Path(tempfile.mkdtemp(prefix=f"{_STAGING}{_owner()}-", dir=out))
        try:
            written = save(result, stage, *args, **kwargs)
            final = [out / p.relative_to(stage) for p in written]
            blocked = [f for f in final if f.is_dir() and not f.is_symlink()]
            if blocked:  # checked before anything moves: a failed move half-way would leave two runs mixed
                raise ConfigError(f"{blocked[0]}: a folder where this run writes a file; move or remove it")
            previous = _manifest_files(out)
            theirs = [] if interrupted else foreign_files(out, [f.name for f in final])  # the user's own files
            if theirs:
                raise ConfigError(_foreign_message(theirs[0], out))
            (out / MANIFEST).unlink(missing_ok=True)  # from here until the new one: visibly incomplete
            for p in previous - {f.name for f in final}:
                (out / p).unlink(missing_ok=True)
            for src, dst in zip(written, final):
                os.replace(src, dst)

            atomic_write_text(out / MANIFEST, json.dumps({"dynid_version": __version__, "files": [f.name for f in final]},
                                                          indent=2) + "\n")
        finally:
            shutil.rmtree(stage, ignore_errors=True)
        return final

    wrapper.__doc__ = inspect.cleandoc(save.__doc__ or "") + "\n\n" + _STAGED_SECTIONS
    return wrapper


_STAGED_SECTIONS = """Returns
-------
list of Path
    The files written, in ``out``.

Raises
------
ConfigError
    If ``out`` exists and is not a folder, cannot be created, or holds a folder where the run writes a file, or a file
    no earlier run into it wrote."""
"""The numpydoc sections of every :func:`staged` writer, appended to its docstring."""


_STAGING = ".dynid-staging-"


def _owner() -> str:
    """This process as a staging folder names it: host and process id."""
    return f"{socket.gethostname().replace('-', '_')}-{os.getpid()}"


def _remove_stale_staging(out: Path, age: float = 3600.0) -> None:
    """Remove staging folders of killed runs: at once when the process that made it on this machine is gone, and any
    (another machine's sharing the folder, a folder of an older version) once it is over ``age`` seconds old."""
    host = socket.gethostname().replace("-", "_")
    for folder in out.glob(_STAGING + "*"):
        try:
            if not folder.is_dir():
                continue
            parts = folder.name[len(_STAGING):].split("-")
            dead = len(parts) >= 3 and parts[0] == host and parts[1].isdigit() and not _alive(int(parts[1]))
            if dead or time.time() - folder.stat().st_mtime > age:
                shutil.rmtree(folder, ignore_errors=True)
        except OSError:
            pass


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _manifest_files(out: Path) -> set[str]:
    try:
        files = json.loads((out / MANIFEST).read_text(encoding="utf-8"))["files"]
        return {f for f in files if isinstance(f, str) and "/" not in f and f not in ("", ".", "..")}
    except (OSError, ValueError, KeyError, TypeError):
        return set()


def output_folder(out: str | Path) -> Path:
    """Create an output folder if needed.

    Parameters
    ----------
    out : str or Path

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder, or cannot be created.
    """
    out = check_output_folder(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"out {out}: cannot create the folder ({exc.strerror})", field="out") from None
    return out


def draw_figures(build, *args) -> None:
    """Draw the figure jobs that ``build(*args)`` returns.

    The jobs are callables without arguments, each writing its own file: drawn in the figure process when one waits
    (:func:`figure_process`), else here, on two processes. If the figure process fails, this process draws every job,
    so every file is written or an error is raised.

    Parameters
    ----------
    build : callable
        A module-level function (it is pickled) returning the jobs.
    *args
        Its arguments, picklable.
    """
    global _waiting
    worker, _waiting = _waiting, None  # one use: the process leaves once it has drawn
    if worker is not None and worker.draw(build, args):
        return
    _draw_jobs(build(*args))


def _draw_jobs(jobs) -> None:
    """Run figure jobs on two processes where :func:`dynid.runtime.processes.can_fork`: a forked child draws every
    other job while this process draws the rest (drawing is single-threaded Python; a fork shares the
    imported matplotlib and the data). If the child fails, this process draws its jobs too.
    Call it with no other thread of this process printing (the CLI ends its live progress line first).
    """
    jobs = list(jobs)
    if len(jobs) < 2 or not can_fork():
        for job in jobs:
            job()
        return
    child = start_child(_run, jobs[1::2])  # its half; if it fails, this process draws that half too
    try:
        for job in jobs[0::2]:
            job()
    finally:
        child.join()
    if child.exitcode != 0:
        for job in jobs[1::2]:
            job()


def _run(jobs) -> None:
    for job in jobs:
        job()


class _FigureProcess:
    """A forked child that imports matplotlib while its parent computes, then draws the figures the parent
    sends it (through a pipe) on two processes, and exits with 0 once every file is written."""

    def __init__(self):
        receiving, self._send = pipe()
        self._child = start_child(_figure_process_main, receiving, self._send)
        receiving.close()

    def draw(self, build, args) -> bool:
        """Send the jobs; return whether the child drew them all (false: this process draws them)."""
        try:
            self._send.send((build, args))
        except Exception:  # noqa: BLE001 - data that do not pickle, or a child gone: this process draws
            self.wait()
            return False
        return self.wait() == 0

    def wait(self) -> int:
        """Close the pipe if it is still open (the child then leaves without drawing), wait for the child and
        return its exit code."""
        if self._send is not None:
            self._send.close()
            self._send = None
        if self._child is None:
            return 1
        self._child.join()
        code, self._child = self._child.exitcode, None
        return int(code if code is not None else 1)


def _figure_process_main(receiving, parents_end) -> None:
    """The figure process: import pyplot, wait for ``(build, args)`` and draw (nothing: the parent closed the pipe)."""
    parents_end.close()  # its copy of the sending end: the parent's close is then seen as the end of the pipe
    _warm_up_drawing()
    try:
        build, args = receiving.recv()
    except EOFError:
        return
    _draw_jobs(build(*args))


def _warm_up_drawing() -> None:
    """What every process's first figure pays once, paid ahead of time: pyplot, the 3-D axes, the fonts,
    the mathtext parser, the PNG writer (0.42-0.45 s in all on this project's 2-core machine)."""
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401 - registers the 3-D projection (the tool path)

    fig = plt.figure(figsize=(2, 2))
    ax = fig.add_subplot(111)
    ax.plot([1.0, 2.0], [1e-4, 1e4], label="warm-up")
    ax.set_yscale("log")  # its labels 10^-4 ... 10^4 are mathtext, parsed once per process (7 ms each)
    ax.set_title("warm-up")
    ax.legend()
    fig.savefig(io.BytesIO(), format="png", dpi=20)
    plt.close(fig)


_waiting: _FigureProcess | None = None
"""The figure process of the current :func:`figure_process` block, until :func:`draw_figures` uses it."""


@contextlib.contextmanager
def figure_process(enabled: bool = True):
    """A block within which :func:`draw_figures` hands the figures to a forked process.

    The process, forked on entry, imports matplotlib and warms up drawing while this process computes, so that both
    are off the command's path. Nothing is forked where ``enabled`` is false or :func:`dynid.runtime.processes.can_fork` is
    (outside the CLI's commands, on one core, not on Linux). Enter it with no other Python thread running (before the
    CLI's live progress line starts its thread). On exit the process is waited for (it leaves at once when nothing was
    sent).

    Parameters
    ----------
    enabled : bool
        Fork at all.

    Yields
    ------
    None
    """
    global _waiting
    if not enabled or not can_fork() or _waiting is not None:
        yield
        return
    _waiting = _FigureProcess()
    try:
        yield
    finally:
        worker, _waiting = _waiting, None
        if worker is not None:  # not handed figures: it leaves at once
            worker.wait()


def save_animation(frames, path: Path, fps: float = 10.0) -> None:
    """Write frames as a looping GIF, atomically (Pillow, matplotlib's own dependency).

    Parameters
    ----------
    frames : list of PIL.Image.Image
        :func:`dynid.report.figures.animate_arm`'s.
    path : Path
    fps : float
        Frames per second.
    """
    from PIL import Image

    small = [f.quantize(colors=FIGURE_COLOURS, method=Image.Quantize.FASTOCTREE) for f in frames]
    buf = io.BytesIO()
    small[0].save(buf, format="GIF", save_all=True, append_images=small[1:], duration=int(round(1000 / fps)), loop=0)
    atomic_write_bytes(path, buf.getvalue())


def save_figure(fig_or_axes, path: Path) -> None:
    """Write a figure as PNG, atomically, in :data:`FIGURE_COLOURS` colours.

    The canvas is rendered at 100 dpi and its pixels quantised: line plots on white lose nothing visible, the file is
    a quarter of a full-colour one (the HTML report embeds the files as they are: about 1 MB for a dozen figures),
    and it takes no longer than ``savefig``'s own PNG (about 0.09 s for a 900 × 1440 px figure either way).

    Parameters
    ----------
    fig_or_axes : Figure, Axes or array of Axes
    path : Path
    """
    import matplotlib.pyplot as plt
    from PIL import Image  # matplotlib's own dependency

    fig = fig_or_axes.figure if hasattr(fig_or_axes, "figure") else fig_or_axes.flat[0].figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig.set_dpi(100)
    canvas = FigureCanvasAgg(fig)  # what savefig would render with (a Figure made without pyplot has no canvas of its own)
    canvas.draw()
    image = Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba()).convert("RGB")
    plt.close(fig)
    buf = io.BytesIO()
    image.quantize(colors=FIGURE_COLOURS, method=Image.Quantize.FASTOCTREE).save(buf, format="PNG", compress_level=6)
    atomic_write_bytes(path, buf.getvalue())


FIGURE_COLOURS = 32
"""Colours of a figure's PNG (:func:`save_figure`)."""


from ..identification.fitted_model import RESULTS_SCHEMA_VERSION as SCHEMA_VERSION  # noqa: E402  one number for both

"""Version of the layout of the JSON files dynid writes; raised when a field changes meaning or goes."""


def write_results(path: Path, data: dict, kind: str) -> None:
    """Write a results JSON atomically, headed by what wrote it.

    Parameters
    ----------
    path : Path
    data : dict
        JSON-ready results.
    kind : str
        run, identify, validate, excite, montecarlo or payload; stored with ``schema_version`` and ``dynid_version``.
    """
    write_json(path, {"schema_version": SCHEMA_VERSION, "dynid_version": __version__, "kind": kind, **data})


def save_texts(files: dict[str, str], out: str | Path) -> list[Path]:
    """Write text files into a folder, all of them or none (through a staging folder inside it), with no manifest:
    they are a user's files (``dynid example``), which a later run writing into the same folder never removes
    (:func:`staged` removes an earlier run's files listed in its manifest).

    Parameters
    ----------
    files : dict
        File name (in ``out``) -> text (UTF-8).
    out : str or Path
        The folder (created if needed).

    Returns
    -------
    list of Path
        Files written.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder, or cannot be created.
    """
    out = output_folder(out)
    stage = Path(tempfile.mkdtemp(prefix=f"{_STAGING}{_owner()}-", dir=out))
    try:
        for name, text in files.items():
            atomic_write_text(stage / name, text)
        for name in files:
            os.replace(stage / name, out / name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return [out / name for name in files]
