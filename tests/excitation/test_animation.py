"""Seen before it runs (issue "An excitation safe to run on the real robot", item 3): ``dynid excite --animation``
writes the arm moving along one period among the cell's bodies, as a looping GIF."""

import numpy as np
from PIL import Image, ImageChops

from dynid.excitation.obstacles import Obstacle
from dynid.identification.excite import run_excitation
from dynid.io.config.excitation_config import load_excitation_config
from dynid.report.excitation_run import ANIMATION, ANIMATION_FRAMES, save_excitation
from dynid.report.figures import animate_arm


def test_each_frame_draws_its_pose():
    """Frames of the same pose at the same time are the same picture; another pose is another picture."""
    a = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [0.4, 0.0, 0.9]])
    b = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [-0.3, 0.3, 0.7]])
    tool = np.array([[0.4, 0.0, 0.9], [-0.3, 0.3, 0.7]])
    box = Obstacle("box", np.full(3, 0.2), np.array([0.5, 0.5, 0.2]), name="box")
    frames = animate_arm(np.array([0.0, 1.0, 0.0]), np.stack([a, b, a]), tool, floor=0.0, obstacles=(box,))
    assert len(frames) == 3 and frames[0].size == frames[1].size
    assert ImageChops.difference(frames[0], frames[2]).getbbox() is None
    assert ImageChops.difference(frames[0], frames[1]).getbbox() is not None


def test_dynid_excite_writes_the_animation_only_when_asked(tmp_path):
    cfg = tmp_path / "cell.toml"
    cfg.write_text('robot = "er16"\njoints = 3\n[design]\nstarts = 1\nmaxiter = 20\n[trajectory]\nharmonics = 2\n'
                   'frequency = 0.1\n[workspace]\nfloor = -0.9\n[[workspace.obstacles]]\nname = "table"\nshape = "box"\n'
                   'size = [1.0, 1.0, 0.1]\nposition = [0.0, 1.2, -0.3]\n')
    run = run_excitation(load_excitation_config(cfg))
    plain = {p.name for p in save_excitation(run, tmp_path / "plain")}
    assert ANIMATION not in plain and not (tmp_path / "plain" / ANIMATION).exists()
    written = {p.name for p in save_excitation(run, tmp_path / "moving", animation=True)}
    assert ANIMATION in written
    with Image.open(tmp_path / "moving" / ANIMATION) as gif:
        assert gif.n_frames == ANIMATION_FRAMES and gif.info.get("loop") == 0
        first = gif.convert("RGB")
        gif.seek(ANIMATION_FRAMES // 2)
        assert ImageChops.difference(first, gif.convert("RGB")).getbbox() is not None  # the arm moved
