"""The paper's figures as matplotlib plots. Each function takes ``ax=None`` and never calls ``show()``."""

from __future__ import annotations

import numpy as np


def _axes(ax, n=1, projection=None, figsize=(8, 6)):
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax
    fig = plt.figure(figsize=figsize, constrained_layout=True)
    if projection:
        return fig.add_subplot(111, projection=projection)
    return fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]


def plot_joint_trajectories(t, q, q_min=None, q_max=None, ax=None, title="Excitation trajectory"):
    """Joint positions against time with their limits (paper Figs. 4 and 8). ``q`` (N, n) [rad]."""
    n = q.shape[1]
    axes = _axes(ax, n, figsize=(8, 2.2 * n))
    for j, a in enumerate(np.atleast_1d(axes)):
        a.plot(t, q[:, j], lw=1.2, label=f"q{j + 1}")
        for lim in (q_min, q_max):
            if lim is not None and np.isfinite(lim[j]):
                a.axhline(lim[j], color="tab:red", ls="--", lw=0.8)
        a.set_ylabel(f"q{j + 1} [rad]")
        a.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_title(title)
    np.atleast_1d(axes)[-1].set_xlabel("t [s]")
    return axes


def plot_tool_path(xyz, ax=None, title="Tool path of the excitation trajectory"):
    """3-D path of the tool point (paper Fig. 5); ``xyz`` (N, 3) [m] in the base frame."""
    ax = _axes(ax, projection="3d", figsize=(7, 6))
    ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], lw=1.0)
    ax.scatter(*xyz[0], color="tab:green", label="start")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(title)
    ax.legend()
    return ax


def plot_convergence(history, ax=None, reference=None, title="ABC convergence"):
    """Best objective F (eq. 9) per iteration (paper Fig. 6); optional horizontal reference values."""
    axes = _axes(ax, figsize=(7, 4))
    a = np.atleast_1d(axes)[0]
    a.plot(np.arange(1, len(history) + 1), history, marker=".", label="ABC best F")
    for label, value in (reference or {}).items():
        a.axhline(value, ls="--", lw=1.0, color="gray" if "paper" in label else "tab:orange", label=label)
    a.set_xlabel("iteration")
    a.set_ylabel("objective F (eq. 9) [N·m]")
    a.set_yscale("log")
    a.grid(alpha=0.3, which="both")
    a.legend()
    a.set_title(title)
    return a


def plot_torque_comparison(t, measured, predicted: dict, ax=None, title="Measured and predicted torques"):
    """Measured against predicted joint torques (paper Figs. 7 and 9). ``predicted`` maps a label to (N, n)."""
    n = measured.shape[1]
    axes = _axes(ax, n, figsize=(9, 2.4 * n))
    for j, a in enumerate(np.atleast_1d(axes)):
        a.plot(t, measured[:, j], color="black", lw=1.0, label="measured")
        for label, p in predicted.items():
            a.plot(t, p[:, j], lw=1.0, ls="--", label=label)
        a.set_ylabel(f"τ{j + 1} [N·m]")
        a.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_title(title)
    np.atleast_1d(axes)[0].legend(loc="upper right", fontsize="small")
    np.atleast_1d(axes)[-1].set_xlabel("t [s]")
    return axes
