"""The measured-against-predicted torque figure: its legend stands off the curves it names."""

import numpy as np
import pytest


def _overlaps(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("n_sets", [3, 9])  # dynid identify's sets; dynid run --compare's nine estimators
def test_the_legend_stands_below_the_axes_not_over_the_curves(n_sets):
    """The legend sat in the first axes' upper right corner, over the curves: a Med7 validation log's J1 measured
    torque and two estimates vanished behind it from 13 s on. It is now a row under the last axes' x label, clear of
    every axes, on the figure dynid writes and on the one plot_torque_comparison makes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from dynid.report.figures import TorqueFigure, plot_torque_comparison

    t = np.linspace(0.0, 16.0, 400)
    measured = np.column_stack([np.sin(t), np.cos(t), 0.1 * t])
    predicted = {f"estimate {k}": measured + 0.1 * k for k in range(n_sets)}
    figure = TorqueFigure(3, list(predicted))
    fig = figure.draw(t, measured, predicted, "validation")
    axes = plot_torque_comparison(t, measured, predicted)
    for f, ax in ((fig, figure.axes), (axes[0].figure, axes)):
        f.draw_without_rendering()
        (legend,) = f.legends
        box = legend.get_window_extent()
        assert [text.get_text() for text in legend.get_texts()] == ["measured", *predicted]
        assert not any(_overlaps(box, a.get_window_extent()) for a in ax)
        assert not _overlaps(box, ax[-1].xaxis.label.get_window_extent())
        assert all(a.get_legend() is None for a in ax)
    plt.close("all")


def test_a_prismatic_joints_axes_say_newtons_and_metres():
    """A sliding joint's force and position are drawn in N and m, the turning ones' in N·m and rad."""
    from dynid.model.robot import default_limits
    from dynid.report.figures import TorqueFigure, plot_excitation_states

    figure = TorqueFigure(3, ["model"], prismatic=(True, False, False))
    assert [a.get_ylabel() for a in figure.axes] == ["f1 [N]", "τ2 [N·m]", "τ3 [N·m]"]
    t = np.linspace(0.0, 1.0, 20)
    x = np.zeros((20, 2))
    ax = plot_excitation_states(t, {"optimised": (x, x, x, x)}, default_limits(2), prismatic=(True, False))
    assert [a.get_ylabel() for a in ax[0]] == ["joint 1: q [m]", "dq [m/s]", "ddq [m/s²]", "f [N]"]
    assert [a.get_ylabel() for a in ax[1]] == ["joint 2: q [rad]", "dq [rad/s]", "ddq [rad/s²]", "τ [N·m]"]
