"""The paper's figures as matplotlib plots. Each function takes ``ax=None`` and never calls ``show()``."""

from __future__ import annotations

import numpy as np

MAX_POINTS = 2500
"""Points drawn per line at most: more cannot be told apart at a figure's resolution, and each one costs
drawing and layout time (a 1 kHz log has 25 000 per line)."""


def _thin(t, *series):
    """Every k-th sample of ``t`` and of each series (time along axis 0) so that at most MAX_POINTS remain."""
    step = max(1, -(-len(t) // MAX_POINTS))
    return (np.asarray(t)[::step],) + tuple(np.asarray(x)[::step] for x in series)


def fixed_layout(fig, left=0.85, right=0.25, top=0.45, bottom=0.55, hspace=0.35) -> None:
    """Margins in inches, whatever the figure's size: matplotlib's automatic (constrained) layout measures every
    tick label and costs more than drawing the figure (0.2 s each, most of dynid run's figures).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    left, right, top, bottom : float
        Margins [inch].
    hspace : float
        Height between panels, as a fraction of a panel's height.
    """
    w, h = fig.get_size_inches()
    fig.subplots_adjust(left=left / w, right=1 - right / w, top=1 - top / h, bottom=bottom / h, hspace=hspace)


def _title(ax, title: str) -> None:
    """Set a 2-D axes' title at a fixed height: matplotlib otherwise measures the top of the axes' tick labels
    to place it (0.03 s a figure). dynid's axes have nothing on top, so the title lands on the same pixels."""
    ax.set_title(title, y=1.0)


def _axes(ax, n=1, projection=None, figsize=(8, 6)):
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax
    fig = plt.figure(figsize=figsize)
    if projection:
        return fig.add_subplot(111, projection=projection)
    fixed_layout(fig)
    return fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]


def plot_joint_trajectories(t, q, q_min=None, q_max=None, ax=None, title="Excitation trajectory"):
    """Joint positions against time with their limits (paper Figs. 4 and 8).

    Parameters
    ----------
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    q_min, q_max : (n_dof,) arrays [rad], optional
        Drawn dashed.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = q.shape[1]
    axes = _axes(ax, n, figsize=(8, 2.2 * n))
    t, q = _thin(t, q)
    for j, a in enumerate(np.atleast_1d(axes)):
        a.plot(t, q[:, j], lw=1.2, label=f"q{j + 1}")
        for lim in (q_min, q_max):
            if lim is not None and np.isfinite(lim[j]):
                a.axhline(lim[j], color="tab:red", ls="--", lw=0.8)
        a.set_ylabel(f"q{j + 1} [rad]")
        a.grid(alpha=0.3)
    _title(np.atleast_1d(axes)[0], title)
    np.atleast_1d(axes)[-1].set_xlabel("t [s]")
    return axes


def plot_tool_path(xyz, ax=None, title="Tool path of the excitation trajectory", others=None, box=None, floor=None,
                   obstacles=()):
    """3-D path of the tool point (paper Fig. 5).

    Parameters
    ----------
    xyz : (N, 3) array [m]
        In the base frame.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str
    others : dict, optional
        label -> another (M, 3) path, drawn dashed.
    box : (box_min, box_max), optional
        The workspace box; its finite edges are drawn.
    floor : float, optional
        Height of a floor plane drawn under the paths [m].
    obstacles : sequence of dynid.excitation.obstacles.Obstacle
        The cell's bodies, drawn as wireframes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    ax = _axes(ax, projection="3d", figsize=(7, 6))
    for k, ob in enumerate(obstacles):
        _draw_obstacle(ax, ob, label="the cell's bodies" if k == 0 else None)
    for label, path in (others or {}).items():
        ax.plot(path[:, 0], path[:, 1], path[:, 2], lw=0.8, ls="--", color="gray", label=label)
    ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], lw=1.0, label="tool path" if others else None)
    ax.scatter(*xyz[0], color="tab:green", label="start")
    pts = np.concatenate([xyz] + list((others or {}).values()))
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    if box is not None and np.any(np.isfinite(np.asarray(box))):
        bmin = np.where(np.isfinite(box[0]), box[0], lo)
        bmax = np.where(np.isfinite(box[1]), box[1], hi)
        corners = np.array([[x, y, z] for x in (bmin[0], bmax[0]) for y in (bmin[1], bmax[1]) for z in (bmin[2], bmax[2])])
        for i in range(8):
            for k in range(i + 1, 8):
                if np.sum(corners[i] != corners[k]) == 1:
                    ax.plot(*corners[[i, k]].T, color="tab:red", lw=0.6, ls=":")
    if floor is not None and np.isfinite(floor):
        xx, yy = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]])
        ax.plot_surface(xx, yy, np.full_like(xx, floor), color="tab:brown", alpha=0.2)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(title)
    ax.legend()
    return ax


def _draw_obstacle(ax, ob, label=None) -> None:
    """A box's edges, or a cylinder's or sphere's wireframe, in its pose (:meth:`Obstacle.geometry`)."""
    rot = np.asarray(ob.geometry()[1].getRotation())
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 16), np.linspace(0, 1, 7))
    if ob.shape == "box":
        half = 0.5 * ob.size
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
        pts = corners @ rot.T + ob.position
        edges = [(i, k) for i in range(8) for k in range(i + 1, 8) if np.sum(corners[i] != corners[k]) == 1]
        for n, (i, k) in enumerate(edges):
            ax.plot(*pts[[i, k]].T, color="tab:purple", lw=1.0, label=label if n == 0 else None)
        return
    if ob.shape == "cylinder":
        local = np.stack([ob.size[0] * np.cos(u), ob.size[0] * np.sin(u), (v - 0.5) * ob.size[1]], axis=-1)
    else:
        polar = np.pi * v
        local = ob.size[0] * np.stack([np.sin(polar) * np.cos(u), np.sin(polar) * np.sin(u), np.cos(polar)], axis=-1)
    pts = local @ rot.T + ob.position
    ax.plot_wireframe(pts[..., 0], pts[..., 1], pts[..., 2], color="tab:purple", lw=0.6, label=label)


def animate_arm(t, skeleton, tool, title="The excitation, before it runs", floor=None, obstacles=()):
    """The arm's skeleton moving along a trajectory among the cell's bodies, as frames of a GIF (issue "An excitation
    safe to run on the real robot", item 3: seen before it runs).

    Parameters
    ----------
    t : (F,) array [s]
        Each frame's time.
    skeleton : (F, P, 3) array [m]
        Each frame's chain of points in the base frame: the base, the joint origins, the tool point (NaN rows break
        the line: a robot's branches).
    tool : (N, 3) array [m]
        The whole tool path, drawn thin under the arm.
    title : str
    floor : float, optional
        Height of the floor plane [m].
    obstacles : sequence of dynid.excitation.obstacles.Obstacle
        The cell's bodies, drawn as wireframes.

    Returns
    -------
    list of PIL.Image.Image
        One RGB image per frame (:func:`dynid.report.output.save_animation` writes them).
    """
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image  # matplotlib's own dependency

    ax = plot_tool_path(tool, title=title, floor=floor, obstacles=obstacles)
    pts = np.concatenate([skeleton.reshape(-1, 3), tool])
    lo, hi = np.nanmin(pts, axis=0), np.nanmax(pts, axis=0)  # NaN rows break the lines between branches
    centre, half = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo)) + 0.05
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    (arm,) = ax.plot(*skeleton[0].T, color="black", lw=3, marker="o", ms=4, label="the arm (its joint origins)")
    ax.get_legend().remove()
    fig = ax.figure
    fig.legend(*ax.get_legend_handles_labels(), loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.set_size_inches(6, 5.5)
    fig.set_dpi(80)
    canvas = FigureCanvasAgg(fig)
    frames = []
    for k in range(skeleton.shape[0]):
        arm.set_data_3d(*skeleton[k].T)
        ax.set_title(f"{title}: t = {t[k]:.1f} s", y=1.0)
        canvas.draw()
        frames.append(Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba()).convert("RGB"))
    plt.close(fig)
    return frames


def plot_clearance(t, series: dict, ax=None, title="How close the links come to the cell"):
    """Smallest distance over time to each of the cell's bodies and to the floor (issue "An excitation safe to run
    on the real robot", item 3).

    Parameters
    ----------
    t : (N,) array [s]
    series : dict
        label -> (N,) distances [m] beyond the links' capsules (below 0: inside the clearance).
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    a = np.atleast_1d(_axes(ax, figsize=(8, 4)))[0]
    for label, d in series.items():
        a.plot(t, d, lw=1.0, label=label)
    a.axhline(0.0, color="tab:red", lw=0.8, ls=":", label="the clearance")
    a.set_xlabel("t [s]")
    a.set_ylabel("distance beyond the capsules [m]")
    a.set_title(title)
    a.grid(alpha=0.3)
    a.legend()
    return a


def plot_convergence(histories, ax=None, reference=None, title="ABC convergence", xlabel="iteration"):
    """Best objective F (eq. 9) against iterations or evaluations (paper Fig. 6).

    Parameters
    ----------
    histories : dict or array
        label -> ``(x, best_F)``; a bare (T,) array is the ABC's best F per iteration.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    reference : dict, optional
        label -> F [N·m] drawn as a horizontal line.
    title, xlabel : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    axes = _axes(ax, figsize=(7, 4))
    a = np.atleast_1d(axes)[0]
    if not isinstance(histories, dict):
        h = np.asarray(histories)
        histories = {"ABC best F": (np.arange(1, len(h) + 1), h)}
    for label, (x, y) in histories.items():
        a.plot(x, y, marker="." if len(x) <= 100 else None, label=label)
    colors = iter(["black", "tab:purple", "tab:brown", "tab:olive"])
    for label, value in (reference or {}).items():
        a.axhline(value, ls="--", lw=1.0, color="gray" if "paper" in label else next(colors, "tab:orange"), label=label)
    a.set_xlabel(xlabel)
    a.set_ylabel("objective F (eq. 9) [N·m]")
    a.set_yscale("log")
    a.grid(alpha=0.3, which="both")
    a.legend(fontsize="small")
    _title(a, title)
    return a


def plot_method_comparison(labels, validation_error, parameter_error, ax=None,
                           title="Estimators on the validation trajectory"):
    """Relative validation error per joint (grouped bars, log scale) and parameter error per estimator.

    Parameters
    ----------
    labels : sequence of str
        One per estimator.
    validation_error : (n_estimators, n_dof) array [%]
    parameter_error : (n_estimators,) array [%]
        ``‖β̂−β‖/‖β‖``.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig = plt.figure(figsize=(9, 6))
        fixed_layout(fig, hspace=0.45)
        ax = fig.subplots(2, 1)
    a, b = ax
    err = np.asarray(validation_error, dtype=float)
    m, n = err.shape
    width = 0.8 / n
    x = np.arange(m)
    for j in range(n):
        a.bar(x + (j - (n - 1) / 2) * width, err[:, j], width, label=f"joint {j + 1}")
    a.set_xticks(x, labels)
    a.set_yscale("log")
    a.set_ylabel("validation error [%]")
    a.legend(fontsize="small", ncol=n)
    a.grid(alpha=0.3, axis="y", which="both")
    _title(a, title)
    b.bar(x, parameter_error, color="tab:gray")
    b.set_xticks(x, labels)
    b.set_yscale("log")
    b.set_ylabel("‖β̂−β‖/‖β‖ [%]")
    b.grid(alpha=0.3, axis="y", which="both")
    return ax


def plot_std_over_bound(levels, labels, ratios, ax=None,
                        title="Monte Carlo: std / √CRB of every base parameter"):
    """One panel per noise level: ``std/√CRB`` of every parameter (dots) for each estimator; 1 = efficient.

    Parameters
    ----------
    levels : (n_levels,) array [A]
    labels : sequence of str
        One per estimator.
    ratios : list of (n_levels, n_params) arrays
        One per estimator.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    n_levels = len(levels)
    if ax is None:
        fig = plt.figure(figsize=(max(6, 1.1 * len(labels) + 2), 2.6 * n_levels), constrained_layout=True)
        ax = fig.subplots(n_levels, 1, sharex=True, squeeze=False)[:, 0]
    rng = np.random.default_rng(0)  # horizontal jitter of the dots only
    for li, a in enumerate(ax):
        for m, r in enumerate(ratios):
            y = np.asarray(r[li], dtype=float)
            a.plot(m + rng.uniform(-0.2, 0.2, y.size), y, ".", alpha=0.7)
            a.plot([m - 0.3, m + 0.3], [np.nanmedian(y)] * 2, color="black", lw=1.5)
        a.axhline(1.0, color="gray", ls="--", lw=1.0)
        a.set_yscale("log")
        a.set_ylabel(f"σ = {levels[li]:g} A\nstd / √CRB")
        a.grid(alpha=0.3, axis="y", which="both")
    ax[-1].set_xticks(np.arange(len(labels)), labels)
    _title(ax[0], title + " (bars: medians)")
    return ax


def plot_noise_level_study(levels, labels, std_ratios, bias_ratios, ax=None,
                           title="Monte Carlo: spread and bias against the current noise level"):
    """Median over the parameters of ``std/√CRB`` (left) and ``|bias|/√CRB`` (right) against the current noise
    level (Monte Carlo study).

    Parameters
    ----------
    levels : (n_levels,) array [A]
    labels : sequence of str
        One per estimator.
    std_ratios, bias_ratios : list of (n_levels, n_params) arrays
        One per estimator.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig = plt.figure(figsize=(10, 4), constrained_layout=True)
        ax = fig.subplots(1, 2)
    for label, s, b in zip(labels, std_ratios, bias_ratios):
        ax[0].plot(levels, np.nanmedian(s, axis=1), marker="o", label=label)
        ax[1].plot(levels, np.nanmedian(b, axis=1), marker="o", label=label)
    for a, name in zip(ax, ("median std / √CRB", "median |bias| / √CRB")):
        a.axhline(1.0, color="gray", ls="--", lw=1.0)
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("current noise σ [A]")
        a.set_ylabel(name)
        a.grid(alpha=0.3, which="both")
    ax[0].legend(fontsize="small")
    ax[0].figure.suptitle(title)
    return ax


def _torque_axes(fig, n: int):
    """``n`` stacked axes sharing x, with a fixed layout (the automatic one costs more than drawing)."""
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    fig.subplots_adjust(left=0.09, right=0.98, top=1 - 0.45 / (2.4 * n), bottom=0.95 / (2.4 * n), hspace=0.3)
    return axes  # the bottom inch holds the x label and the legend (:class:`TorqueFigure`), off the curves


def plot_torque_comparison(t, measured, predicted: dict, ax=None, title="Measured and predicted torques"):
    """Measured against predicted joint torques (paper Figs. 7 and 9).

    Parameters
    ----------
    t : (N,) array [s]
    measured : (N, n_dof) array [N·m]
    predicted : dict
        label -> (N, n_dof) array [N·m].
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    below = ax is None
    if ax is None:
        import matplotlib.pyplot as plt

        n = measured.shape[1]
        ax = _torque_axes(plt.figure(figsize=(9, 2.4 * n)), n)
    figure = TorqueFigure(measured.shape[1], list(predicted), axes=ax, legend_below=below)
    figure.draw(t, measured, predicted, title)
    return figure.axes


class TorqueFigure:
    """Measured against predicted torques of several datasets, drawn one after the other on the same figure:
    its axes, ticks and lines are built once and only their data change (building them costs more than
    drawing; ``dynid identify`` draws one figure per validation log).

    Parameters
    ----------
    n_dof : int
    labels : sequence of str
        The predicted parameter sets, in the order of the ``predicted`` dicts given to :meth:`draw`.
    axes : sequence of ``n_dof`` Axes, optional
        Where to draw (default: a new figure, not managed by pyplot).
    legend_below : bool, optional
        The legend in a row under the axes, where :func:`_torque_axes` leaves room (default: on a new figure), rather
        than in the first axes, where it hid the curves it names (a Med7 log's J1 from 13 s on).
    prismatic : sequence of bool, optional
        Which joints slide: their axes say force [N] rather than torque [N·m].
    """

    def __init__(self, n_dof: int, labels, axes=None, *, legend_below: bool | None = None, prismatic=()):
        below = axes is None if legend_below is None else legend_below
        if axes is None:
            from matplotlib.figure import Figure

            axes = _torque_axes(Figure(figsize=(9, 2.4 * n_dof)), n_dof)
        self.labels = list(labels)
        self.axes = np.atleast_1d(axes)
        self.fig = self.axes[0].figure
        self.lines = []
        for j, a in enumerate(self.axes):
            row = [a.plot([], [], color="black", lw=1.0, label="measured")[0]]
            row += [a.plot([], [], lw=1.0, ls="--", label=label)[0] for label in self.labels]
            self.lines.append(row)
            a.set_ylabel(f"f{j + 1} [N]" if j < len(prismatic) and prismatic[j] else f"τ{j + 1} [N·m]")
            a.grid(alpha=0.3)
        if below:
            self.fig.legend(handles=self.lines[0], loc="lower center", ncol=min(len(self.lines[0]), 5), fontsize="small",
                            frameon=False)
        else:
            self.axes[0].legend(loc="best", fontsize="small")
        self.axes[-1].set_xlabel("t [s]")

    def draw(self, t, measured, predicted: dict, title: str):
        """The figure with one dataset's curves (the figure is reused from dataset to dataset).

        Parameters
        ----------
        t : (N,) array [s]
        measured : (N, n_dof) array [N·m]
        predicted : dict
            label -> (N, n_dof) predicted torques [N·m].
        title : str

        Returns
        -------
        matplotlib.figure.Figure
        """
        t, measured, *preds = _thin(t, measured, *(predicted[k] for k in self.labels))
        for j, (a, row) in enumerate(zip(self.axes, self.lines)):
            for line, y in zip(row, [measured] + preds):
                line.set_data(t, y[:, j])
            a.relim()
            a.autoscale_view()
        _title(self.axes[0], title)
        return self.fig


def plot_excitation_states(t, states: dict, limits, ax=None, title="Excitation trajectory and its limits", prismatic=()):
    """Positions, velocities, accelerations and torques of each joint with their limits (paper Fig. 4).

    Parameters
    ----------
    t : (N,) array [s]
    states : dict
        label -> ``(q, dq, ddq, tau)``, each (N, n_dof) [rad, rad/s, rad/s², N·m]; the first drawn solid, the others
        dashed.
    limits : Limits
        ``q_min, q_max, dq_max, ddq_max, tau_max`` (n_dof,) each; infinite ones are omitted.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    title : str
    prismatic : sequence of bool, optional
        Which joints slide: their rows say m, m/s, m/s² and N.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    first = next(iter(states.values()))[0]
    n = first.shape[1]
    if ax is None:
        fig = plt.figure(figsize=(13, 2.0 * n + 0.6), constrained_layout=True)
        ax = fig.subplots(n, 4, sharex=True, squeeze=False)
    step = max(1, -(-len(t) // MAX_POINTS))
    t = np.asarray(t)[::step]
    states = {k: tuple(np.asarray(x)[::step] for x in v) for k, v in states.items()}
    columns = (("q [rad]", limits.q_min, limits.q_max), ("dq [rad/s]", -limits.dq_max, limits.dq_max),
               ("ddq [rad/s²]", -limits.ddq_max, limits.ddq_max), ("τ [N·m]", -limits.tau_max, limits.tau_max))
    for c, (unit, lo, hi) in enumerate(columns):
        for j in range(n):
            a = ax[j, c]
            for i, (label, values) in enumerate(states.items()):
                a.plot(t, values[c][:, j], lw=1.1 if i == 0 else 0.8, ls="-" if i == 0 else "--", label=label)
            for lim in (lo[j], hi[j]):
                if np.isfinite(lim):
                    a.axhline(lim, color="tab:red", ls=":", lw=0.9)
            said = unit.replace("rad", "m").replace("τ [N·m]", "f [N]") if j < len(prismatic) and prismatic[j] else unit
            a.set_ylabel(f"joint {j + 1}: {said}" if c == 0 else said)  # metres and newtons along a sliding joint
            a.grid(alpha=0.3)
        ax[-1, c].set_xlabel("t [s]")
    ax[0, 0].legend(loc="upper right", fontsize="small")
    ax[0, 0].figure.suptitle(title)
    return ax
